#include "skelgraph/gesture/features.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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
constexpr const char* kSide[2] = {"left", "right"};

double to_vertical(const Vector3d& v) {
  const double n = v.norm();
  if (n < 1e-9) return std::nan("");
  return std::acos(std::clamp(v.y() / n, -1.0, 1.0));
}

// Per-arm values of the angle sets (thesis8, extended, hands, arm).
enum ArmValue { UpperArmAngle, ForearmAngle, ElbowBend, HandHeight, HandAngle, HandLength, ForearmOut, HandForward, HandSway, kArmValues };
constexpr const char* kArmValueNames[kArmValues] = {"upper_arm_angle", "forearm_angle", "elbow_bend",
                                                    "hand_height",     "hand_angle",    "hand_length",
                                                    "forearm_out",     "hand_forward",  "hand_sway"};
// HandSway is the spread (standard deviation) of the hand segment's outward
// direction over the last kSwayWindow s: a hand waved from the wrist swings it.
constexpr double kSwayWindow = 0.5;

// The values of a set (before speeds), and which of them get a speed.
struct Layout {
  std::vector<std::string> values;
  int speeds = 0;        // the first `speeds` values get a speed
  bool signed_speed = false;
  std::vector<std::pair<int, int>> arm;  // angle sets: (side, ArmValue) of each value
};

// Blocks of per-arm values: within a block, the left arm's then the right's
// (the thesis's order: left upper arm, left forearm, right upper arm, right forearm).
std::vector<std::vector<ArmValue>> arm_blocks(FeatureSet s, int* speed_blocks) {
  *speed_blocks = s == FeatureSet::Extended ? 2 : 1;  // the first blocks get speeds
  switch (s) {
    case FeatureSet::Extended: return {{UpperArmAngle, ForearmAngle}, {ElbowBend, HandHeight}};
    case FeatureSet::Hands: return {{UpperArmAngle, ForearmAngle, ForearmOut}, {HandAngle, HandLength}};
    case FeatureSet::Arm: return {{UpperArmAngle, ForearmAngle, ForearmOut}, {HandForward, HandSway}};
    default: return {{UpperArmAngle, ForearmAngle}};
  }
}

Layout layout(FeatureSet s) {
  Layout l;
  if (s == FeatureSet::Body) {
    // Hands (with speeds), then knees (with speeds), then elbows.
    for (const char* side : kSide)
      for (const char* axis : {"out", "up", "forward"}) l.values.push_back(std::string(side) + "_hand_" + axis);
    for (const char* side : kSide) l.values.push_back(std::string(side) + "_knee_up");
    l.speeds = static_cast<int>(l.values.size());
    for (const char* side : kSide)
      for (const char* axis : {"out", "up", "forward"}) l.values.push_back(std::string(side) + "_elbow_" + axis);
    l.signed_speed = true;
    return l;
  }
  int speed_blocks = 0;
  const auto blocks = arm_blocks(s, &speed_blocks);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (int side = 0; side < 2; ++side)
      for (const ArmValue v : blocks[b]) {
        l.values.push_back(std::string(kSide[side]) + "_" + kArmValueNames[v]);
        l.arm.emplace_back(side, v);
      }
    if (static_cast<int>(b) < speed_blocks) l.speeds = static_cast<int>(l.values.size());
  }
  return l;
}

// The raw values of one frame, NaN where a joint they need is not good.
VectorXd frame_values(const std::vector<std::pair<int, int>>& arm_layout, int n, FeatureSet set, const skeleton::Skeleton& s,
                      const Wrists* wrists, float min_confidence) {
  const auto good = [&](JointId j) { return s[j].confidence >= min_confidence && s[j].position.allFinite(); };
  VectorXd a = VectorXd::Constant(n, std::nan(""));
  if (set == FeatureSet::Body) {
    if (!good(JointId::LeftShoulder) || !good(JointId::RightShoulder)) return a;
    const Vector3d up(0, 1, 0);
    Vector3d across = s[JointId::RightShoulder].position - s[JointId::LeftShoulder].position;
    across.y() = 0;
    if (across.norm() < 1e-6) return a;
    across.normalize();
    const Vector3d forward = up.cross(across);
    for (int side = 0; side < 2; ++side) {
      const Arm& arm = kArms[side];
      if (!good(arm.elbow) || !good(arm.hand)) continue;
      const Vector3d sh = s[arm.shoulder].position, el = s[arm.elbow].position, ha = s[arm.hand].position;
      const double len = (el - sh).norm() + (ha - el).norm();
      if (len < 1e-6) continue;
      const Vector3d out = side == 0 ? Vector3d(-across) : across;
      const auto body = [&](const Vector3d& v) -> Vector3d { return Vector3d(v.dot(out), v.dot(up), v.dot(forward)) / len; };
      a.segment<3>(3 * side) = body(ha - sh);
      a.segment<3>(8 + 3 * side) = body(el - sh);
    }
    constexpr JointId kLegs[2][3] = {{JointId::LeftHip, JointId::LeftKnee, JointId::LeftFoot},
                                     {JointId::RightHip, JointId::RightKnee, JointId::RightFoot}};
    for (int side = 0; side < 2; ++side) {
      const auto& leg = kLegs[side];
      if (!good(leg[0]) || !good(leg[1]) || !good(leg[2])) continue;
      const Vector3d hip = s[leg[0]].position, knee = s[leg[1]].position, foot = s[leg[2]].position;
      const double len = (knee - hip).norm() + (foot - knee).norm();
      if (len > 1e-6) a(6 + side) = (knee.y() - hip.y()) / len;
    }
    return a;
  }
  double arm_value[2][kArmValues];
  for (int side = 0; side < 2; ++side) {
    double* v = arm_value[side];
    std::fill(v, v + kArmValues, std::nan(""));
    const Arm& arm = kArms[side];
    const Vector3d sh = s[arm.shoulder].position, el = s[arm.elbow].position, ha = s[arm.hand].position;
    if (good(arm.shoulder) && good(arm.elbow)) v[UpperArmAngle] = to_vertical(el - sh);
    if (good(arm.elbow) && good(arm.hand)) v[ForearmAngle] = to_vertical(ha - el);
    if (good(arm.shoulder) && good(arm.elbow) && good(arm.hand)) {
      const Vector3d u = el - sh, f = ha - el;
      if (u.norm() > 1e-9 && f.norm() > 1e-9) {
        v[ElbowBend] = std::acos(std::clamp(u.normalized().dot(f.normalized()), -1.0, 1.0));
        v[HandHeight] = (ha.y() - sh.y()) / u.norm();
      }
    }
    if (good(JointId::LeftShoulder) && good(JointId::RightShoulder) && good(arm.elbow) && good(arm.hand)) {
      // The forearm's direction along the body's outward axis (horizontal, along the shoulders): a wave swings it.
      Vector3d across = s[JointId::RightShoulder].position - s[JointId::LeftShoulder].position;
      across.y() = 0;
      const Vector3d f = ha - el;
      if (across.norm() > 1e-6 && f.norm() > 1e-9)
        v[ForearmOut] = f.normalized().dot(side == 0 ? Vector3d(-across.normalized()) : across.normalized());
    }
    if (wrists && good(arm.elbow) && good(arm.hand)) {
      const Vector3d wr = side == 0 ? wrists->left : wrists->right;
      const Vector3d forearm = wr - el, hand = ha - wr;
      if (wr.allFinite() && forearm.norm() > 1e-9 && hand.norm() > 1e-9) {
        v[HandAngle] = to_vertical(hand);
        v[HandLength] = hand.norm() / forearm.norm();
        // The hand segment in the body's frame: forward (horizontal, square to
        // the shoulders) in arm lengths, and its outward direction (HandSway's spread).
        Vector3d across = s[JointId::RightShoulder].position - s[JointId::LeftShoulder].position;
        across.y() = 0;
        const double len = (el - sh).norm() + forearm.norm();
        if (good(JointId::LeftShoulder) && good(JointId::RightShoulder) && good(arm.shoulder) && across.norm() > 1e-6 && len > 1e-9) {
          across.normalize();
          const Vector3d forward = Vector3d::UnitY().cross(across);
          v[HandForward] = hand.dot(forward) / len;
          v[HandSway] = hand.normalized().dot(side == 0 ? Vector3d(-across) : across);
        }
      }
    }
  }
  for (std::size_t i = 0; i < arm_layout.size(); ++i)
    a(static_cast<Eigen::Index>(i)) = arm_value[arm_layout[i].first][arm_layout[i].second];
  return a;
}

}  // namespace

std::vector<std::string> feature_names(FeatureSet set) {
  const Layout l = layout(set);
  std::vector<std::string> out = l.values;
  for (int i = 0; i < l.speeds; ++i) out.push_back(l.values[static_cast<std::size_t>(i)] + "_speed");
  return out;
}

std::vector<int> mirror_permutation(FeatureSet set) {
  const auto names = feature_names(set);
  std::vector<int> perm(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string other = names[i];
    if (other.rfind("left_", 0) == 0) other = "right_" + other.substr(5);
    else if (other.rfind("right_", 0) == 0) other = "left_" + other.substr(6);
    perm[i] = static_cast<int>(std::find(names.begin(), names.end(), other) - names.begin());
  }
  return perm;
}

Sequence mirrored(const Sequence& x, FeatureSet set) {
  const auto perm = mirror_permutation(set);
  if (static_cast<std::size_t>(x.cols()) != perm.size())
    throw ModelError("features have " + std::to_string(x.cols()) + " columns; the '" + feature_set_name(set) + "' set has " +
                     std::to_string(perm.size()));
  Sequence out(x.rows(), x.cols());
  for (std::size_t i = 0; i < perm.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = x.col(perm[i]);
  return out;
}

Sequence right_handed(const Sequence& x, FeatureSet set, bool* was) {
  const auto names = feature_names(set);
  const Layout l = layout(set);
  if (static_cast<std::size_t>(x.cols()) < l.values.size())
    throw ModelError("features have " + std::to_string(x.cols()) + " columns; the '" + feature_set_name(set) + "' set has " +
                     std::to_string(names.size()));
  double side[2] = {0, 0};
  if (x.rows() > 1)
    for (std::size_t i = 0; i < l.values.size(); ++i) {
      const int s = names[i].rfind("left_", 0) == 0 ? 0 : names[i].rfind("right_", 0) == 0 ? 1 : -1;
      if (s < 0) continue;
      const auto c = x.col(static_cast<Eigen::Index>(i));
      side[s] += (c.array() - c.mean()).square().sum() / static_cast<double>(x.rows() - 1);
    }
  const bool m = side[0] > side[1];
  if (was) *was = m;
  return m ? mirrored(x, set) : x;
}

Span motion_span(const Sequence& x, FeatureSet set, double share, int rest_frames, int pad) {
  const Eigen::Index T = x.rows(), V = static_cast<Eigen::Index>(layout(set).values.size());
  if (T == 0) return {0, 0};
  const Eigen::Index r = std::clamp<Eigen::Index>(rest_frames, 1, T);
  const auto values = x.leftCols(V);
  const Eigen::RowVectorXd start = values.topRows(r).colwise().mean(), end = values.bottomRows(r).colwise().mean();
  Eigen::VectorXd d(T);
  for (Eigen::Index t = 0; t < T; ++t) d(t) = std::min((values.row(t) - start).norm(), (values.row(t) - end).norm());
  const double limit = share * d.maxCoeff();
  Eigen::Index first = -1, last = -1;
  for (Eigen::Index t = 0; t < T; ++t)
    if (d(t) > limit && limit > 0) {
      if (first < 0) first = t;
      last = t;
    }
  if (first < 0) return {0, T};
  return {std::max<Eigen::Index>(0, first - pad), std::min(T, last + 1 + pad)};
}

std::optional<FeatureSet> feature_set_from_name(const std::string& name) {
  if (name == "thesis8") return FeatureSet::Thesis8;
  if (name == "extended") return FeatureSet::Extended;
  if (name == "body") return FeatureSet::Body;
  if (name == "hands") return FeatureSet::Hands;
  if (name == "arm") return FeatureSet::Arm;
  return std::nullopt;
}

const char* feature_set_name(FeatureSet set) {
  switch (set) {
    case FeatureSet::Thesis8: return "thesis8";
    case FeatureSet::Extended: return "extended";
    case FeatureSet::Body: return "body";
    case FeatureSet::Hands: return "hands";
    case FeatureSet::Arm: return "arm";
  }
  return "?";
}

FeatureStream::FeatureStream(FeatureOptions options) : o_(options) {
  const Layout l = layout(options.set);
  arm_ = l.arm;
  for (std::size_t i = 0; i < arm_.size(); ++i)
    if (arm_[i].second == HandSway) sway_.push_back({static_cast<int>(i), {}});
  values_ = static_cast<int>(l.values.size());
  speeds_ = l.speeds;
  signed_speed_ = l.signed_speed;
  reset();
}

void FeatureStream::reset() {
  last_good_ = VectorXd::Zero(values_);
  have_.assign(static_cast<std::size_t>(values_), false);
  first_ = true;
  last_dt_ = 1.0 / 30;
  for (auto& w : sway_) w.second.clear();
}

int FeatureStream::size() const { return values_ + speeds_; }

bool needs_wrists(FeatureSet set) { return set == FeatureSet::Hands || set == FeatureSet::Arm; }

bool one_arm(FeatureSet set) { return set == FeatureSet::Arm; }

std::vector<Eigen::Index> model_columns(FeatureSet set) {
  const auto names = feature_names(set);
  std::vector<Eigen::Index> keep;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (!one_arm(set) || names[i].rfind("left_", 0) != 0) keep.push_back(static_cast<Eigen::Index>(i));
  return keep;
}

Sequence model_view(const Sequence& x, FeatureSet set) {
  if (!one_arm(set)) return x;
  const auto keep = model_columns(set);
  Sequence out(x.rows(), static_cast<Eigen::Index>(keep.size()));
  for (std::size_t i = 0; i < keep.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = x.col(keep[i]);
  return out;
}

VectorXd FeatureStream::step(const skeleton::Skeleton& s, bool* complete, VectorXd* raw, const Wrists* wrists) {
  const VectorXd a = frame_values(arm_, values_, o_.set, s, wrists, o_.min_confidence);
  if (raw) *raw = a;
  bool all = true;
  double dt = last_dt_;
  if (!first_ && s.stamp_ns > last_ns_) dt = std::max(o_.min_interval, static_cast<double>(s.stamp_ns - last_ns_) * 1e-9);
  VectorXd out(size());
  for (int i = 0; i < values_; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    double speed = 0.0;
    if (std::isfinite(a(i))) {
      if (have_[iu] && !first_) speed = (a(i) - last_good_(i)) / dt;
      last_good_(i) = a(i);
      have_[iu] = true;
      out(i) = a(i);
    } else {
      all = false;
      out(i) = last_good_(i);  // held (0 until a good value has been seen); its speed is 0
    }
    if (i < speeds_) out(values_ + i) = signed_speed_ ? speed : std::abs(speed);
  }
  // HandSway: the direction's spread over the last kSwayWindow s (held values included; 0 on the first frame).
  for (auto& [i, window] : sway_) {
    window.emplace_back(s.stamp_ns, out(i));
    while (window.size() > 1 && static_cast<double>(s.stamp_ns - window.front().first) * 1e-9 > kSwayWindow) window.pop_front();
    double mean = 0, sq = 0;
    for (const auto& [t, v] : window) mean += v;
    mean /= static_cast<double>(window.size());
    for (const auto& [t, v] : window) sq += (v - mean) * (v - mean);
    out(i) = std::sqrt(sq / static_cast<double>(window.size()));
  }
  last_ns_ = s.stamp_ns;
  last_dt_ = dt;
  first_ = false;
  if (complete) *complete = all;
  return out;
}

Features features_of(const std::vector<skeleton::Skeleton>& frames, const FeatureOptions& options,
                     const std::vector<Wrists>* wrists) {
  if (wrists && wrists->size() != frames.size())
    throw std::invalid_argument("features_of: " + std::to_string(wrists->size()) + " wrist frames for " +
                                std::to_string(frames.size()) + " skeletons");
  FeatureStream fs(options);
  Features f;
  f.x.resize(static_cast<Eigen::Index>(frames.size()), fs.size());
  const int values = fs.values();
  std::vector<int> first_good(static_cast<std::size_t>(values), -1);
  for (std::size_t t = 0; t < frames.size(); ++t) {
    bool complete = false;
    VectorXd raw;
    const Wrists* w = wrists ? &(*wrists)[t] : nullptr;
    f.x.row(static_cast<Eigen::Index>(t)) = fs.step(frames[t], &complete, &raw, w).transpose();
    f.complete.push_back(complete);
    for (int i = 0; i < values; ++i)
      if (std::isfinite(raw(i)) && first_good[static_cast<std::size_t>(i)] < 0) first_good[static_cast<std::size_t>(i)] = static_cast<int>(t);
  }
  // Frames before a value's first good one take it (the stream had nothing to hold yet).
  for (int i = 0; i < values; ++i) {
    const int g = first_good[static_cast<std::size_t>(i)];
    for (int t = 0; t < g; ++t) f.x(t, i) = f.x(g, i);
  }
  return f;
}

}  // namespace skelgraph::gesture
