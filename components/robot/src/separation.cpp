#include "skelgraph/robot/separation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace skelgraph::robot {

using skeleton::JointId;

const char* safety_state_name(SafetyState s) {
  switch (s) {
    case SafetyState::Run: return "RUN";
    case SafetyState::Reduced: return "REDUCED";
    case SafetyState::ProtectiveStop: return "PROTECTIVE_STOP";
  }
  return "PROTECTIVE_STOP";
}

double protective_distance(const SeparationParams& p, const StoppingModel& stop, double separation_m, double v_r,
                           double reaction_s, double person_uncertainty_m) {
  const double v_h = separation_m < p.near_m ? p.human_speed_near : p.human_speed;
  const double t_s = stop.time_s(v_r);
  return v_h * (reaction_s + t_s) + v_r * reaction_s + stop.distance_m(v_r) + p.intrusion_m + person_uncertainty_m +
         p.robot_uncertainty_m;
}

std::vector<Capsule> person_capsules(const skeleton::Skeleton& s, std::vector<std::vector<JointId>>* joints) {
  struct Part {
    const char* name;
    JointId a, b;
    double radius;
  };
  static const Part parts[] = {
      {"head", JointId::Head, JointId::Head, 0.12},
      {"trunk", JointId::Neck, JointId::Torso, 0.17},
      {"left_upper_arm", JointId::LeftShoulder, JointId::LeftElbow, 0.06},
      {"left_forearm", JointId::LeftElbow, JointId::LeftHand, 0.05},
      {"left_hand", JointId::LeftHand, JointId::LeftHand, 0.09},  // (fingers beyond the wrist-centred joint)
      {"right_upper_arm", JointId::RightShoulder, JointId::RightElbow, 0.06},
      {"right_forearm", JointId::RightElbow, JointId::RightHand, 0.05},
      {"right_hand", JointId::RightHand, JointId::RightHand, 0.09},
      {"pelvis", JointId::LeftHip, JointId::RightHip, 0.12},
      {"left_thigh", JointId::LeftHip, JointId::LeftKnee, 0.08},
      {"left_shin", JointId::LeftKnee, JointId::LeftFoot, 0.06},
      {"right_thigh", JointId::RightHip, JointId::RightKnee, 0.08},
      {"right_shin", JointId::RightKnee, JointId::RightFoot, 0.06},
  };
  std::vector<Capsule> out;
  if (joints) joints->clear();
  for (const auto& part : parts) {
    const auto& a = s[part.a];
    const auto& b = s[part.b];
    if (a.confidence <= 0 || b.confidence <= 0) continue;
    out.push_back({a.position, b.position, part.radius, part.name});
    if (joints) joints->push_back({part.a, part.b});
  }
  // The trunk reaches down to the hips.
  const auto& torso = s[JointId::Torso];
  const auto& lh = s[JointId::LeftHip];
  const auto& rh = s[JointId::RightHip];
  if (torso.confidence > 0 && lh.confidence > 0 && rh.confidence > 0) {
    out.push_back({torso.position, 0.5 * (lh.position + rh.position), 0.17, "trunk"});
    if (joints) joints->push_back({JointId::Torso, JointId::LeftHip, JointId::RightHip});
  }
  return out;
}

PersonSeparation separation_to(const skeleton::Skeleton& person, const std::vector<Capsule>& robot) {
  std::vector<std::vector<JointId>> joints;
  const auto parts = person_capsules(person, &joints);
  const auto c = closest(parts, robot);
  PersonSeparation out;
  out.distance = c.distance;
  if (!std::isfinite(c.distance)) return out;
  out.part = parts[c.first].name;
  out.robot_part = robot[c.second].name;
  for (const auto j : joints[c.first]) out.uncertainty_m = std::max(out.uncertainty_m, skeleton::radius_95(person[j]));
  return out;
}

SafetyDecision decide(const SeparationParams& p, const StoppingModel& stop, const SeparationInput& in) {
  SafetyDecision d;
  d.protective_m = protective_distance(p, stop, in.separation_m, in.robot_speed, in.reaction_s, in.person_uncertainty_m);
  d.protective_full_m =
      protective_distance(p, stop, in.separation_m, in.robot_max_speed, in.reaction_s, in.person_uncertainty_m);
  const auto stop_because = [&](const std::string& why) {
    d.state = SafetyState::ProtectiveStop;
    d.speed_scale = 0;
    d.reason = why;
    return d;
  };
  // Fail-safe first: what the decision would rest on is not known well enough.
  std::ostringstream why;
  if (!std::isfinite(in.people_age_s)) return stop_because("no people data yet (no sensor frames, no fused skeletons)");
  if (!std::isfinite(in.robot_age_s)) return stop_because("no robot state yet");
  if (in.people_age_s > p.max_people_age_s) {
    why << "people data " << std::lround(in.people_age_s * 1e3) << " ms old (limit " << std::lround(p.max_people_age_s * 1e3)
        << " ms)";
    return stop_because(why.str());
  }
  if (in.robot_age_s > p.max_robot_age_s) {
    why << "robot state " << std::lround(in.robot_age_s * 1e3) << " ms old (limit " << std::lround(p.max_robot_age_s * 1e3)
        << " ms)";
    return stop_because(why.str());
  }
  if (in.coverage_lost) return stop_because("a sensor covering the robot's surroundings is lost and no other covers it");
  if (in.unplaced_person) return stop_because("a person fusion cannot place");
  if (!in.stop_gesture.empty()) return stop_because(in.stop_gesture);
  if (!std::isfinite(in.separation_m)) {
    d.state = SafetyState::Run;
    d.speed_scale = 1.0;
    d.reason = "nobody in the cell";
    return d;
  }
  const auto describe = [&](double s_p) {
    std::ostringstream os;
    os.setf(std::ios::fixed);
    os.precision(2);
    os << in.closest << ": " << in.separation_m << " m, S_p " << s_p << " m";
    return os.str();
  };
  if (in.separation_m < d.protective_m) return stop_because(describe(d.protective_m));
  if (in.separation_m >= d.protective_full_m + p.margin_m) {
    d.state = SafetyState::Run;
    d.speed_scale = 1.0;
    d.reason = describe(d.protective_full_m);
    return d;
  }
  // Reduced: the highest speed whose S_p (plus the margin) still fits; S_p grows with speed.
  const auto fits = [&](double scale) {
    return protective_distance(p, stop, in.separation_m, scale * in.robot_max_speed, in.reaction_s,
                               in.person_uncertainty_m) +
               p.margin_m <=
           in.separation_m;
  };
  if (!fits(p.min_scale)) return stop_because(describe(d.protective_m) + " (no useful speed fits)");
  double lo = p.min_scale, hi = 1.0;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fits(mid) ? lo : hi) = mid;
  }
  d.state = SafetyState::Reduced;
  d.speed_scale = lo;
  d.reason = describe(protective_distance(p, stop, in.separation_m, lo * in.robot_max_speed, in.reaction_s,
                                          in.person_uncertainty_m));
  return d;
}

SafetyDecision StopLatch::apply(SafetyDecision d, double now_s) {
  if (d.state == SafetyState::ProtectiveStop) {
    stopped_ = true;
    clear_ = false;
    return d;
  }
  if (!stopped_) return d;
  if (!clear_) {
    clear_ = true;
    clear_since_s_ = now_s;
  }
  if (now_s - clear_since_s_ >= release_s_) {
    stopped_ = false;
    return d;
  }
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  os << "holding the stop until clear for " << release_s_ << " s (" << (now_s - clear_since_s_) << " s so far): " << d.reason;
  d.state = SafetyState::ProtectiveStop;
  d.speed_scale = 0;
  d.reason = os.str();
  return d;
}

}  // namespace skelgraph::robot
