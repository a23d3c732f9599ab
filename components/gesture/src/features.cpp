#include "skelgraph/gesture/features.hpp"

#include <algorithm>
#include <cmath>

namespace skelgraph::gesture {

using Eigen::Vector3d;
using Eigen::VectorXd;
using skeleton::JointId;

namespace {

struct Arm {
  JointId shoulder, elbow, hand;
};
constexpr Arm kArms[2] = {{JointId::LeftShoulder, JointId::LeftElbow, JointId::LeftHand},
                          {JointId::RightShoulder, JointId::RightElbow, JointId::RightHand}};

double to_vertical(const Vector3d& v) {
  const double n = v.norm();
  if (n < 1e-9) return std::nan("");
  return std::acos(std::clamp(v.y() / n, -1.0, 1.0));
}

int angle_count(FeatureSet s) { return s == FeatureSet::Thesis8 ? 4 : 8; }

}  // namespace

std::vector<std::string> feature_names(FeatureSet set) {
  std::vector<std::string> angles;
  for (const char* side : {"left", "right"}) {
    angles.push_back(std::string(side) + "_upper_arm_angle");
    angles.push_back(std::string(side) + "_forearm_angle");
  }
  if (set == FeatureSet::Extended) {
    for (const char* side : {"left", "right"}) {
      angles.push_back(std::string(side) + "_elbow_bend");
      angles.push_back(std::string(side) + "_hand_height");
    }
  }
  std::vector<std::string> out = angles;
  for (const auto& a : angles) out.push_back(a + "_speed");
  return out;
}

std::optional<FeatureSet> feature_set_from_name(const std::string& name) {
  if (name == "thesis8") return FeatureSet::Thesis8;
  if (name == "extended") return FeatureSet::Extended;
  return std::nullopt;
}

FeatureStream::FeatureStream(FeatureOptions options) : o_(options), angles_(angle_count(options.set)) { reset(); }

void FeatureStream::reset() {
  last_good_ = VectorXd::Zero(angles_);
  have_.assign(static_cast<std::size_t>(angles_), false);
  first_ = true;
  last_dt_ = 1.0 / 30;
}

int FeatureStream::size() const { return 2 * angles_; }

VectorXd FeatureStream::step(const skeleton::Skeleton& s, bool* complete) {
  const auto good = [&](JointId j) { return s[j].confidence >= o_.min_confidence && s[j].position.allFinite(); };
  VectorXd a = VectorXd::Constant(angles_, std::nan(""));
  for (int side = 0; side < 2; ++side) {
    const Arm& arm = kArms[side];
    const Vector3d sh = s[arm.shoulder].position, el = s[arm.elbow].position, ha = s[arm.hand].position;
    if (good(arm.shoulder) && good(arm.elbow)) a(2 * side) = to_vertical(el - sh);
    if (good(arm.elbow) && good(arm.hand)) a(2 * side + 1) = to_vertical(ha - el);
    if (o_.set == FeatureSet::Extended && good(arm.shoulder) && good(arm.elbow) && good(arm.hand)) {
      const Vector3d u = el - sh, f = ha - el;
      if (u.norm() > 1e-9 && f.norm() > 1e-9) {
        a(4 + 2 * side) = std::acos(std::clamp(u.normalized().dot(f.normalized()), -1.0, 1.0));
        a(4 + 2 * side + 1) = (ha.y() - sh.y()) / u.norm();
      }
    }
  }
  bool all = true;
  double dt = last_dt_;
  if (!first_ && s.stamp_ns > last_ns_) dt = static_cast<double>(s.stamp_ns - last_ns_) * 1e-9;
  VectorXd out(size());
  for (int i = 0; i < angles_; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    if (std::isfinite(a(i))) {
      out(angles_ + i) = have_[iu] && !first_ ? std::abs(a(i) - last_good_(i)) / dt : 0.0;
      last_good_(i) = a(i);
      have_[iu] = true;
      out(i) = a(i);
    } else {
      all = false;
      out(i) = last_good_(i);  // held (0 until a good value has been seen)
      out(angles_ + i) = 0.0;
    }
  }
  last_ns_ = s.stamp_ns;
  last_dt_ = dt;
  first_ = false;
  if (complete) *complete = all;
  return out;
}

Features features_of(const std::vector<skeleton::Skeleton>& frames, const FeatureOptions& options) {
  FeatureStream fs(options);
  Features f;
  f.x.resize(static_cast<Eigen::Index>(frames.size()), fs.size());
  const int angles = fs.size() / 2;
  std::vector<int> first_good(static_cast<std::size_t>(angles), -1);
  for (std::size_t t = 0; t < frames.size(); ++t) {
    bool complete = false;
    f.x.row(static_cast<Eigen::Index>(t)) = fs.step(frames[t], &complete).transpose();
    f.complete.push_back(complete);
  }
  // Frames before an angle's first good value take that value (the stream had nothing to hold yet).
  for (std::size_t t = 0; t < frames.size(); ++t) {
    const auto& s = frames[t];
    for (int side = 0; side < 2; ++side) {
      const Arm& arm = kArms[side];
      const auto good = [&](JointId j) { return s[j].confidence >= options.min_confidence && s[j].position.allFinite(); };
      const bool upper = good(arm.shoulder) && good(arm.elbow), fore = good(arm.elbow) && good(arm.hand);
      const bool both = upper && good(arm.hand);
      const bool ok[4] = {upper, fore, both, both};
      for (int k = 0; k < 2; ++k) {
        const int i = 2 * side + k;
        if (ok[k] && first_good[static_cast<std::size_t>(i)] < 0) first_good[static_cast<std::size_t>(i)] = static_cast<int>(t);
      }
      if (angles == 8) {
        for (int k = 0; k < 2; ++k) {
          const int i = 4 + 2 * side + k;
          if (ok[2 + k] && first_good[static_cast<std::size_t>(i)] < 0) first_good[static_cast<std::size_t>(i)] = static_cast<int>(t);
        }
      }
    }
  }
  for (int i = 0; i < angles; ++i) {
    const int g = first_good[static_cast<std::size_t>(i)];
    for (int t = 0; t < g; ++t) f.x(t, i) = f.x(g, i);
  }
  return f;
}

}  // namespace skelgraph::gesture
