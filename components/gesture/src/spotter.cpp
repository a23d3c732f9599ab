#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/skeleton/json_number.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace skelgraph::gesture {

using Eigen::Vector3d;
using skeleton::JointId;

namespace {
constexpr JointId kArm[2][3] = {{JointId::LeftShoulder, JointId::LeftElbow, JointId::LeftHand},
                                {JointId::RightShoulder, JointId::RightElbow, JointId::RightHand}};
constexpr const char* kSideName[2] = {"left", "right"};

}  // namespace

const char* motion_state_name(MotionState s) {
  switch (s) {
    case MotionState::Resting: return "resting";
    case MotionState::Moving: return "moving";
    case MotionState::Holding: return "holding";
  }
  return "?";
}

std::optional<Vector3d> intersect(const Vector3d& origin, const Vector3d& direction, const Surface& s) {
  const double denom = s.normal.dot(direction);
  if (std::abs(denom) < 1e-9) return std::nullopt;
  const double k = s.normal.dot(s.point - origin) / denom;
  if (k <= 0) return std::nullopt;
  return Vector3d(origin + k * direction);
}

namespace {
double deg(double r) { return r * 180.0 / M_PI; }
double rad(double d) { return d * M_PI / 180.0; }
// Elevation and azimuth (towards `out` positive, from the forward direction) of a direction.
std::pair<double, double> el_az(const Vector3d& d, const Vector3d& out) {
  const Vector3d up = Vector3d::UnitY(), fwd = up.cross(out).normalized();
  // fwd: for the right arm out = the person's right, up x right = forward... up to sign; only differences are used.
  return {std::asin(std::clamp(d.normalized().y(), -1.0, 1.0)), std::atan2(d.dot(out), d.dot(fwd))};
}
}  // namespace

namespace {
Eigen::Vector3d parse_xyz(const std::string& s, const std::string& whole) {
  Eigen::Vector3d v;
  std::istringstream in(s);
  char c1 = 0, c2 = 0;
  if (!(in >> v.x() >> c1 >> v.y() >> c2 >> v.z()) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
    throw std::invalid_argument("surface '" + whole + "': expected x,y,z numbers, got '" + s + "'");
  return v;
}

}  // namespace

Surface parse_surface(const std::string& text) {
  const auto a = text.find(':');
  if (a == std::string::npos || a == 0) throw std::invalid_argument("surface '" + text + "': expected name:x,y,z[:nx,ny,nz]");
  Surface s;
  s.name = text.substr(0, a);
  const auto b = text.find(':', a + 1);
  s.point = parse_xyz(text.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1), text);
  if (b != std::string::npos) {
    s.normal = parse_xyz(text.substr(b + 1), text);
    if (s.normal.norm() < 1e-9) throw std::invalid_argument("surface '" + text + "': the normal is zero");
    s.normal.normalize();
  }
  return s;
}

ArmFrame::ArmFrame(const Vector3d& across, bool right) : up(Vector3d::UnitY()) {
  Vector3d a(across.x(), 0, across.z());
  a = a.norm() > 1e-9 ? a.normalized() : Vector3d::UnitX();
  out = right ? a : Vector3d(-a);
  forward = Vector3d(-a).cross(up);  // left x up: the way the torso faces
}

Vector3d corrected(const Vector3d& direction, const Vector3d& out, const PointingCorrection& c) {
  if (out.norm() < 1e-9) return direction;
  const Vector3d o = Vector3d(out.x(), 0, out.z()).normalized();
  const Vector3d up = Vector3d::UnitY(), fwd = up.cross(o).normalized();
  auto [el, az] = el_az(direction, o);
  el -= rad(c.elevation);
  az -= rad(c.azimuth_out);
  return (std::cos(el) * (std::cos(az) * fwd + std::sin(az) * o) + std::sin(el) * up).normalized();
}

PointingCorrection ray_offset(const Vector3d& direction, const Vector3d& truth, const Vector3d& out) {
  const Vector3d o = Vector3d(out.x(), 0, out.z()).normalized();
  const auto [e1, a1] = el_az(direction, o);
  const auto [e0, a0] = el_az(truth, o);
  double da = a1 - a0;
  while (da > M_PI) da -= 2 * M_PI;
  while (da < -M_PI) da += 2 * M_PI;
  return {deg(e1 - e0), deg(da)};
}

Spotter::Spotter(const Classifier& classifier, SpotterOptions options)
    : c_(classifier), o_(std::move(options)), features_(FeatureOptions{classifier.feature_set(), skeleton::kTracked}) {}

std::vector<SpottedEvent> Spotter::step(const skeleton::Skeleton& s, const Wrists* wrists) {
  if (!wrists && needs_wrists(c_.feature_set()))
    throw ModelError(std::string("the model uses the '") + feature_set_name(c_.feature_set()) +
                     "' features, which need wrist joints; this skeleton stream carries none");
  std::vector<SpottedEvent> out;
  person_ = s.person_id;
  const std::int64_t t = s.stamp_ns;
  // A person unseen for `lost` s was lost by the trackers and found again (a
  // fused id outlives that): the fresh skeletons settle again, as at the start.
  if (first_ns_ < 0 || (have_last_ && static_cast<double>(t - last_ns_) * 1e-9 > o_.lost)) first_ns_ = t;
  // The pointing event gathered over the hold goes out: at `aim` (moving:
  // false), or when the arm moves again, without the hold's last `window` s,
  // when the hand was already on its way (the speed is measured over that
  // window, so it says "moving" that late). Stamped with its last sample
  // (or when it was decided, if that was later).
  const auto send_aimed = [&](int side, bool moving) {
    if (!aiming_ || aiming_side_ != side) return;
    if (moving && static_cast<double>(t - aiming_hold_ns_) * 1e-9 < o_.hold + o_.confirm) {
      aiming_.reset();  // not held long enough to confirm it
      return;
    }
    auto& rays = rays_[side];
    const auto cut = t - static_cast<std::int64_t>(o_.window * 1e9);
    if (moving) {
      while (rays.size() > 1 && rays.back().t > cut) rays.pop_back();
    }
    if (auto e = release_aiming(rays, rays.empty() ? aiming_->end_ns : std::max(aiming_->end_ns, rays.back().t))) out.push_back(*e);
  };
  const double dt = have_last_ && t > last_ns_ ? static_cast<double>(t - last_ns_) * 1e-9 : 1.0 / 30;
  const Eigen::VectorXd x = features_.step(s, nullptr, nullptr, wrists);

  if (s[JointId::LeftShoulder].confidence >= skeleton::kTracked && s[JointId::RightShoulder].confidence >= skeleton::kTracked) {
    Vector3d a = s[JointId::RightShoulder].position - s[JointId::LeftShoulder].position;
    a.y() = 0;
    if (a.norm() > 0.05) across_ = a.normalized();
  }
  // The trunk's lean (a reach to a bench bends it; pointing stands upright):
  // how far the neck is off the torso horizontally. A distance, not an angle:
  // a tracker's error is centimetres whatever the body's size, and a short
  // trunk's angle would be mostly that error.
  double lean_m = std::numeric_limits<double>::quiet_NaN();
  if (s[JointId::Torso].confidence >= skeleton::kTracked && s[JointId::Neck].confidence >= skeleton::kTracked) {
    Vector3d off = s[JointId::Neck].position - s[JointId::Torso].position;
    off.y() = 0;
    lean_m = off.norm();
  }
  // Hands: speed, rest, extension, holds.
  bool at_rest[2], still[2];
  for (int side = 0; side < 2; ++side) {
    const auto& j = kArm[side];
    const bool good = s[j[0]].confidence >= skeleton::kTracked && s[j[1]].confidence >= skeleton::kTracked &&
                      s[j[2]].confidence >= skeleton::kTracked;
    if (!good) {  // no evidence: counts as at rest and still, ends any hold
      send_aimed(side, true);
      at_rest[side] = still[side] = true;
      hold_since_[side] = -1;
      rays_[side].clear();
      trail_[side].clear();
      have_hand_[side] = false;
      continue;
    }
    const Vector3d sh = s[j[0]].position, el = s[j[1]].position, ha = s[j[2]].position;
    const double len = (el - sh).norm() + (ha - el).norm();
    // Speed: displacement of the smoothed hand over the last `window` s (tracker noise averages out).
    last_hand_[side] = have_hand_[side] ? Vector3d(last_hand_[side] + (1.0 - std::exp(-dt / o_.smoothing)) * (ha - last_hand_[side])) : ha;
    have_hand_[side] = true;
    auto& h = trail_[side];
    h.emplace_back(t, last_hand_[side]);
    while (h.size() > 2 && static_cast<double>(t - h[1].first) * 1e-9 >= o_.window) h.pop_front();
    const double span = static_cast<double>(t - h.front().first) * 1e-9;
    speed_[side] = span > 0 ? (h.back().second - h.front().second).norm() / span : 0.0;
    Vector3d reach = ha - sh;
    reach.y() = 0;
    at_rest[side] = ha.y() < sh.y() - o_.rest_drop * len && reach.norm() < o_.rest_reach * len;
    still[side] = speed_[side] < o_.still_speed;
    const bool settled = static_cast<double>(t - first_ns_) * 1e-9 >= o_.warmup;
    // Extended and raised: an arm hanging straight is no pointing, even where a
    // tracker's error puts its hand outside the rest zone.
    const double raised = std::acos(std::clamp((sh.y() - ha.y()) / std::max((ha - sh).norm(), 1e-9), -1.0, 1.0));
    const bool extended = settled && !at_rest[side] && (ha - sh).norm() >= o_.extended * len && raised >= o_.min_raise * M_PI / 180;
    if (still[side] && extended) {
      if (hold_since_[side] < 0) {
        hold_since_[side] = t;
        rays_[side].clear();
      }
      const ArmFrame arm(across_, side == 1);
      const auto& pc = c_.pointing_correction();
      const Vector3d sh0 = sh - arm.to_world(pc.shoulder), ha0 = ha - arm.to_world(pc.hand);
      rays_[side].push_back({t, sh0, (ha0 - sh0).normalized(), false, (ha - sh).norm() / std::max(len, 1e-9), lean_m});
      if (aiming_ && aiming_side_ == side && static_cast<double>(t - hold_since_[side]) * 1e-9 >= std::max(o_.aim, o_.hold + o_.confirm)) {
        send_aimed(side, false);
      }
      if (rays_[side].size() > best_rays_.size()) best_rays_ = rays_[side], best_side_ = side;
    } else {
      send_aimed(side, true);
      hold_since_[side] = -1;
      rays_[side].clear();
    }
  }
  // A ray of this frame with the other arm held out (extended and still) as well.
  for (int side = 0; side < 2; ++side) {
    if (hold_since_[side] >= 0 && hold_since_[1 - side] >= 0 && !rays_[side].empty() && rays_[side].back().t == t) {
      rays_[side].back().both = true;
      if (best_side_ == side && !best_rays_.empty() && best_rays_.back().t == t) best_rays_.back().both = true;
    }
  }
  have_last_ = true;
  last_ns_ = t;
  state_ = at_rest[0] && at_rest[1] && still[0] && still[1] ? MotionState::Resting
           : still[0] && still[1]                          ? MotionState::Holding
                                                           : MotionState::Moving;

  // Segments.
  const auto pad_ns = static_cast<std::int64_t>(o_.pad * 1e9);
  if (!open_) {
    before_.push_back({t, x});
    while (!before_.empty() && t - before_.front().t > pad_ns) before_.pop_front();
    if (state_ != MotionState::Resting) {
      open_ = true;
      fired_ = false;
      rest_since_ = -1;
      segment_.assign(before_.begin(), before_.end());
      before_.clear();
      best_rays_.clear();
    }
    return out;
  }
  segment_.push_back({t, x});
  // Pointing, early: an extended arm held still long enough.
  if (!fired_) {
    for (int side = 0; side < 2; ++side) {
      if (hold_since_[side] < 0 || static_cast<double>(t - hold_since_[side]) * 1e-9 < o_.hold) continue;
      if (auto e = decide(t, true)) {
        if (e->label == o_.point_label && (o_.aim > o_.hold || o_.confirm > 0)) {  // decided; the ray is gathered until the arm moves or `aim` has passed
          aiming_side_ = e->arm == kSideName[1] ? 1 : 0;
          aiming_hold_ns_ = hold_since_[aiming_side_];
          aiming_ = std::move(e);
        } else {
          out.push_back(*e);
        }
        fired_ = true;
      }
      break;
    }
  }
  if (state_ == MotionState::Resting) {
    if (rest_since_ < 0) rest_since_ = t;
    if (static_cast<double>(t - rest_since_) * 1e-9 >= o_.settle) {
      auto e = close(t, true);
      out.insert(out.end(), e.begin(), e.end());
    }
  } else {
    rest_since_ = -1;
    if (static_cast<double>(t - segment_.front().t) * 1e-9 > o_.max_length) {
      auto e = close(t, false);
      out.insert(out.end(), e.begin(), e.end());
    }
  }
  return out;
}

std::vector<SpottedEvent> Spotter::close(std::int64_t now_ns, bool final) {
  std::vector<SpottedEvent> out;
  if (aiming_) {  // the segment ends while the ray is still being gathered (a hold cut short by the end of data)
    if (static_cast<double>(now_ns - aiming_hold_ns_) * 1e-9 < o_.hold + o_.confirm) aiming_.reset();  // unconfirmed
    else if (auto e = release_aiming(rays_[aiming_side_].empty() ? best_rays_ : rays_[aiming_side_], now_ns)) out.push_back(*e);
  }
  const double length = segment_.empty() ? 0.0 : static_cast<double>(segment_.back().t - segment_.front().t) * 1e-9;
  if (!fired_ && length >= o_.min_length) {
    if (auto e = decide(now_ns, false)) out.push_back(*e);
  }
  segment_.clear();
  best_rays_.clear();
  fired_ = false;
  rest_since_ = -1;
  if (final) open_ = false;
  return out;
}

std::optional<SpottedEvent> Spotter::release_aiming(const Rays& rays, std::int64_t end_ns) {
  SpottedEvent e = std::move(*aiming_);
  aiming_.reset();
  aim(e, rays, aiming_side_);
  e.end_ns = end_ns;
  if (!pointing_posture(e)) return std::nullopt;
  return e;
}

bool Spotter::pointing_posture(const SpottedEvent& e) const {
  if (o_.min_straightness > 0 && e.straightness < o_.min_straightness) return false;
  if (o_.max_lean_m > 0 && std::isfinite(e.lean_m) && e.lean_m > o_.max_lean_m) return false;
  return true;
}

void Spotter::aim(SpottedEvent& e, const Rays& rays, int side) const {
  if (rays.empty() || side < 0) return;
  Vector3d origin = Vector3d::Zero(), dir = Vector3d::Zero();
  double straight = 0.0, lean = 0.0;
  int leans = 0;
  for (const auto& r : rays) {
    origin += r.origin;
    dir += r.direction;
    straight += r.straight;
    if (std::isfinite(r.lean_m)) lean += r.lean_m, ++leans;
  }
  origin /= static_cast<double>(rays.size());
  e.straightness = straight / static_cast<double>(rays.size());
  e.lean_m = leans > 0 ? lean / leans : std::numeric_limits<double>::quiet_NaN();
  e.has_ray = dir.norm() > 1e-9;
  e.ray_origin = origin;
  e.arm = kSideName[side];
  e.out = ArmFrame(across_, side == 1).out;
  e.ray_direction = corrected(dir.normalized(), e.out, c_.pointing_correction());
  e.has_target = false;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& s : o_.surfaces) {
    const auto hit = intersect(origin, e.ray_direction, s);
    if (hit && (*hit - origin).norm() < nearest) {
      nearest = (*hit - origin).norm();
      e.has_target = true;
      e.target = *hit;
      e.target_name = s.name;
    }
  }
}

std::optional<SpottedEvent> Spotter::decide(std::int64_t now_ns, bool early) {
  if (segment_.size() < 2) return std::nullopt;
  Sequence x(static_cast<Eigen::Index>(segment_.size()), segment_.front().x.size());
  for (std::size_t i = 0; i < segment_.size(); ++i) x.row(static_cast<Eigen::Index>(i)) = segment_[i].x.transpose();
  const Decision d = c_.classify(x);
  const std::string& label = c_.labels()[static_cast<std::size_t>(d.label)];
  // "No gesture" is the garbage class where the classifier has one; the
  // rejection threshold only where it has none. Both at once would turn away
  // a gesture its own model wins, merely for being unlike the training clips
  // (a jittery hand: Kinder-Gator subject 734's pointing).
  // A segment no model can explain at all (every score -inf) is never an event.
  if (!std::isfinite(d.scores[static_cast<std::size_t>(d.label)])) return std::nullopt;
  if (d.label == c_.garbage_index() || (d.rejected && c_.garbage_index() < 0)) return std::nullopt;
  const bool point = label == o_.point_label;
  const bool held = std::find(o_.held_labels.begin(), o_.held_labels.end(), label) != o_.held_labels.end();
  if (early && !point && !held) return std::nullopt;
  SpottedEvent e;
  e.label = label;
  e.person_id = person_;
  e.start_ns = segment_.front().t;
  e.end_ns = now_ns;
  e.log_likelihood = d.scores[static_cast<std::size_t>(d.label)];
  e.confidence = 1.0 - std::exp(-std::max(0.0, d.margin));
  if (e.confidence < o_.min_confidence) return std::nullopt;
  if (point) {
    // Early: the arm held out now; at the end: the segment's longest hold.
    int side = -1;
    for (int k = 0; k < 2; ++k)
      if (hold_since_[k] >= 0 && (side < 0 || hold_since_[k] < hold_since_[side])) side = k;
    const bool now = early && side >= 0;
    const auto& rays = now ? rays_[side] : best_rays_;
    if (!now) side = best_side_;
    aim(e, rays, side);
    if (!e.has_ray) return std::nullopt;  // no arm was held out: whatever the models say, this was not pointing
    if (o_.other_arm_free) {
      const auto both = std::count_if(rays.begin(), rays.end(), [](const RaySample& r) { return r.both; });
      if (2 * both > static_cast<std::ptrdiff_t>(rays.size())) return std::nullopt;  // both arms out: not pointing
    }
    if (o_.max_target > 0 && (!e.has_target || (e.target - e.ray_origin).norm() > o_.max_target)) return std::nullopt;
    if (!pointing_posture(e)) return std::nullopt;
  }
  return e;
}

// --- Evaluation ---

SpottingReport score_spotting(const std::vector<SpottedEvent>& events, const std::vector<TruthGesture>& truth,
                              const std::string& label, double slack_s) {
  SpottingReport r;
  r.label = label;
  const auto slack = static_cast<std::int64_t>(slack_s * 1e9);
  std::vector<const TruthGesture*> want;
  for (const auto& g : truth)
    if (g.label == label) want.push_back(&g);
  r.truth = static_cast<int>(want.size());
  std::vector<bool> matched(want.size(), false);
  for (const auto& e : events) {
    if (e.label != label) continue;
    ++r.events;
    bool hit = false;
    for (std::size_t i = 0; i < want.size() && !hit; ++i) {
      const auto& g = *want[i];
      if (matched[i] || e.end_ns < g.start_ns - slack || e.end_ns > g.end_ns + slack) continue;
      matched[i] = hit = true;
      r.latency_s.push_back(static_cast<double>(e.end_ns - g.end_ns) * 1e-9);
      if (g.hold_ns >= 0) r.latency_hold_s.push_back(static_cast<double>(e.end_ns - g.hold_ns) * 1e-9);
      if (g.has_target && e.has_target) r.target_error_m.push_back((e.target - g.target).norm());
      if (g.has_ray && e.has_ray)
        r.ray_error_deg.push_back(std::acos(std::clamp(g.ray_direction.dot(e.ray_direction), -1.0, 1.0)) * 180.0 / M_PI);
    }
    (hit ? r.true_positive : r.false_positive) += 1;
  }
  r.false_negative = r.truth - r.true_positive;
  finish(r);
  return r;
}

SpottingReport combine(const std::vector<SpottingReport>& parts) {
  SpottingReport r;
  for (const auto& p : parts) {
    r.label = p.label;
    r.truth += p.truth;
    r.events += p.events;
    r.true_positive += p.true_positive;
    r.false_positive += p.false_positive;
    r.false_negative += p.false_negative;
    r.latency_s.insert(r.latency_s.end(), p.latency_s.begin(), p.latency_s.end());
    r.latency_hold_s.insert(r.latency_hold_s.end(), p.latency_hold_s.begin(), p.latency_hold_s.end());
    r.target_error_m.insert(r.target_error_m.end(), p.target_error_m.begin(), p.target_error_m.end());
    r.ray_error_deg.insert(r.ray_error_deg.end(), p.ray_error_deg.begin(), p.ray_error_deg.end());
    r.non_gesture_s += p.non_gesture_s;
  }
  finish(r);
  return r;
}

void finish(SpottingReport& r) {
  r.precision = r.events ? static_cast<double>(r.true_positive) / r.events : 0.0;
  r.recall = r.truth ? static_cast<double>(r.true_positive) / r.truth : 0.0;
  r.f1 = r.precision + r.recall > 0 ? 2 * r.precision * r.recall / (r.precision + r.recall) : 0.0;
  r.median_latency_s = stats::median(r.latency_s);
  r.median_latency_hold_s = stats::median(r.latency_hold_s);
  r.median_target_error_m = stats::median(r.target_error_m);
  r.median_ray_error_deg = stats::median(r.ray_error_deg);
  r.max_target_error_m = r.target_error_m.empty() ? std::nan("") : *std::max_element(r.target_error_m.begin(), r.target_error_m.end());
  r.false_per_hour = r.non_gesture_s > 0 ? r.false_positive / (r.non_gesture_s / 3600.0) : std::nan("");
}

nlohmann::json to_json(const SpottingReport& r) {
  return {{"label", r.label},
          {"truth", r.truth},
          {"events", r.events},
          {"true_positive", r.true_positive},
          {"false_positive", r.false_positive},
          {"false_negative", r.false_negative},
          {"precision", r.precision},
          {"recall", r.recall},
          {"f1", r.f1},
          {"median_latency_s", json_number(r.median_latency_s)},
          {"median_latency_from_hold_s", json_number(r.median_latency_hold_s)},
          {"median_target_error_m", json_number(r.median_target_error_m)},
          {"max_target_error_m", json_number(r.max_target_error_m)},
          {"median_ray_error_deg", json_number(r.median_ray_error_deg)},
          {"non_gesture_hours", r.non_gesture_s / 3600.0},
          {"false_per_hour", json_number(r.false_per_hour)},
          {"latency_s", r.latency_s},
          {"ray_error_deg", r.ray_error_deg},
          {"target_error_m", r.target_error_m}};
}

}  // namespace skelgraph::gesture
