#include "skelgraph/sim/scenario.hpp"

#include <algorithm>
#include <optional>
#include <cmath>
#include <stdexcept>

#include "skelgraph/sim/rng.hpp"

namespace skelgraph::sim {

namespace {

constexpr double kPi = M_PI;
double deg(double d) { return d * kPi / 180.0; }
double smoothstep(double u) { return u * u * (3.0 - 2.0 * u); }
double lerp(double a, double b, double u) { return a + (b - a) * u; }

ArmPose lerp(const ArmPose& a, const ArmPose& b, double u) {
  return {lerp(a.elevation, b.elevation, u), lerp(a.azimuth, b.azimuth, u), lerp(a.elbow_flex, b.elbow_flex, u),
          lerp(a.bend_twist, b.bend_twist, u)};
}
LegPose lerp(const LegPose& a, const LegPose& b, double u) {
  return {lerp(a.hip_flex, b.hip_flex, u), lerp(a.knee_flex, b.knee_flex, u)};
}

// Facing `target` (x, z) from `from`.
double heading_towards(const Eigen::Vector2d& from, const Eigen::Vector2d& target) {
  const Eigen::Vector2d d = target - from;
  return std::atan2(d.x(), d.y());
}

// Legs and arms swinging at walking pace (phase in rad).
void gait(BodyPose& p, double phase) {
  const double s = std::sin(phase);
  p.left_leg = {0.30 * s, 0.15 + 0.35 * std::max(0.0, std::sin(phase + kPi / 2))};
  p.right_leg = {-0.30 * s, 0.15 + 0.35 * std::max(0.0, std::sin(phase - kPi / 2))};
  auto swing = [](double v) {
    ArmPose a = arm_rest();
    a.elevation = std::abs(v);
    a.azimuth = v >= 0 ? 0.0 : kPi;
    a.elbow_flex = 0.25;
    return a;
  };
  p.left_arm = swing(-0.30 * s);
  p.right_arm = swing(0.30 * s);
}

BodyPose standing(double heading = 0.0) {
  BodyPose p;
  p.heading = heading;
  p.left_arm = p.right_arm = arm_rest();
  return p;
}

// Writes the key list for one performance of a script.
struct Builder {
  Rng& rng;
  std::vector<Scenario::Key>& keys;
  BodyPose cur;
  double t = 0.0;

  double vary(double d) { return d * rng.uniform(0.9, 1.1); }
  void hold(double d, const std::string& phase) {
    t += vary(d);
    keys.push_back({t, cur, phase, false});
  }
  void to(const BodyPose& p, double d, const std::string& phase, bool linear = false) {
    cur = p;
    t += vary(d);
    keys.push_back({t, cur, phase, linear});
  }
};

BodyPose with_arms(BodyPose p, const ArmPose& left, const ArmPose& right) {
  p.left_arm = left;
  p.right_arm = right;
  return p;
}

void script_360(Builder& b) {
  BodyPose p = with_arms(b.cur, arm_side(), arm_side());
  b.to(p, 1.0, "t_pose");
  b.hold(2.0, "t_pose");
  p.heading += 2 * kPi;
  b.to(p, 9.0, "turn_t_pose", true);
  p = with_arms(p, arm_rest(), arm_rest());
  b.to(p, 1.0, "arms_down");
  p.heading += 2 * kPi;
  b.to(p, 9.0, "turn_arms_down", true);
  b.hold(1.0, "stand");
}

void script_hide(Builder& b) {
  const BodyPose rest = b.cur;
  b.hold(2.0, "stand");
  b.to(with_arms(rest, arm_behind_back(), arm_rest()), 1.0, "hide_left");
  b.hold(4.0, "hide_left");
  b.to(rest, 1.0, "stand");
  b.hold(2.0, "stand");
  b.to(with_arms(rest, arm_rest(), arm_behind_back()), 1.0, "hide_right");
  b.hold(4.0, "hide_right");
  b.to(rest, 1.0, "stand");
  b.hold(2.0, "stand");
  b.to(with_arms(rest, arm_behind_back(), arm_behind_back()), 1.0, "hide_both");
  b.hold(4.0, "hide_both");
  b.to(rest, 1.0, "stand");
}

// How far the hips come down when the knees bend with the feet on the floor.
double crouch_drop(const BodyDimensions& d, const LegPose& leg) {
  const double standing = d.thigh + d.shank;
  return standing - (d.thigh * std::cos(leg.hip_flex) + d.shank * std::cos(leg.knee_flex - leg.hip_flex));
}

void script_box(Builder& b, const BodyDimensions& d) {
  const BodyPose rest = b.cur;
  BodyPose bent = rest;
  bent.trunk_pitch = 1.2;
  bent.left_leg = bent.right_leg = {1.0, 1.6};
  bent.pelvis_drop = crouch_drop(d, bent.left_leg);
  ArmPose reach{1.2, 0.15, 0.1, 0.0};  // hanging straight down from the bent trunk, a little apart
  bent = with_arms(bent, reach, reach);
  BodyPose carry = rest;
  ArmPose hold{deg(45), -0.08, 0.6, 0.0};
  carry = with_arms(carry, hold, hold);
  BodyPose out = rest;
  ArmPose extend{deg(65), -0.08, 0.1, 0.0};
  out = with_arms(out, extend, extend);
  b.hold(2.0, "stand");
  b.to(bent, 1.8, "bend");
  b.hold(0.7, "grab");
  b.to(carry, 1.8, "lift");
  b.to(out, 1.2, "hold_out");
  b.hold(3.0, "hold_out");
  b.to(carry, 1.0, "lower");
  b.to(bent, 1.8, "lower");
  b.hold(0.5, "put_down");
  b.to(rest, 1.8, "stand");
  b.hold(1.0, "stand");
}

// The hiding place is behind the wall (see Scenario::props), to the person's right.
const Eigen::Vector2d kHideSpot{-1.15, 0.0};

void script_occ(Builder& b) {
  const BodyPose rest = b.cur;
  const Eigen::Vector2d home = rest.floor_position;
  for (int i = 0; i < 3; ++i) {
    b.hold(4.0, "stand");
    BodyPose p = rest;
    p.heading = heading_towards(home, kHideSpot);
    b.to(p, 0.6, "turn");
    p.floor_position = kHideSpot;
    b.to(p, 1.6, "walk_away");
    p.heading = rest.heading;
    b.to(p, 0.6, "turn");
    b.hold(2.5, "hidden");
    p.heading = heading_towards(kHideSpot, home);
    b.to(p, 0.6, "turn");
    p.floor_position = home;
    b.to(p, 1.6, "walk_back");
    b.to(rest, 0.6, "turn");
  }
  b.hold(1.0, "stand");
}

void script_sit(Builder& b, double hip_height) {
  const BodyPose rest = b.cur;
  BodyPose seated = rest;
  seated.pelvis_drop = hip_height - 0.50;  // hip joints 0.5 m above the floor on a 0.47 m seat
  seated.trunk_pitch = 0.12;
  seated.left_leg = seated.right_leg = {deg(88), deg(88)};
  const ArmPose on_thigh{0.55, 0.1, 0.9, 0.0};
  seated = with_arms(seated, on_thigh, on_thigh);
  BodyPose rising = seated;  // leaning forward to get up
  rising.trunk_pitch = 0.6;
  for (int i = 0; i < 2; ++i) {
    b.hold(2.0, "stand");
    b.to(seated, 2.0, "sit_down");
    b.hold(5.0, "sitting");
    b.to(rising, 0.8, "stand_up");
    b.to(rest, 1.2, "stand_up");
  }
  b.hold(1.0, "stand");
}

void script_arms(Builder& b) {
  BodyPose p = b.cur;
  // Quarter turns both ways: the thesis's Arms figures (hands 13-14 cm, 95-100 %
  // tracked) rule out the back ever facing the sensor.
  for (double h : {0.0, 45.0, 90.0, 45.0, 0.0, -45.0, -90.0, -45.0, 0.0}) {
    p.heading = deg(h);
    p = with_arms(p, arm_rest(), arm_rest());
    b.to(p, 1.0, "rotate", true);
    b.to(with_arms(p, arm_side(), arm_side()), 1.0, "arms_side");
    b.hold(1.5, "arms_side");
    b.to(p, 1.0, "arms_down");
    b.to(with_arms(p, arm_forward(), arm_forward()), 1.0, "arms_forward");
    b.hold(1.5, "arms_forward");
    b.to(p, 1.0, "arms_down");
  }
}

// Ordinary work at a bench beside a robot, 60 s, with arm motions close to
// pointing that are not pointing: reaching to the bench, picking up and
// placing parts, carrying one round (turning with the arms bent), turning to
// the robot and back, scratching the head, adjusting glasses, and taking a
// tool from a shelf at the side (the arm straight out and held: the pose of
// pointing, at shoulder height). Nobody gestures. Phases name the motion.
void script_work_cell(Builder& b) {
  const BodyPose rest = b.cur;
  const double end = b.t + 60.0;
  while (b.t < end - 1.0) {
    const double u = b.rng.uniform();
    const bool right = b.rng.chance(0.6);
    BodyPose p = rest;
    ArmPose& arm = right ? p.right_arm : p.left_arm;
    std::string phase;
    double hold = 0.0;
    if (u < 0.2) {  // reach to the bench in front, elbow a little bent
      arm = {deg(b.rng.uniform(55.0, 85.0)), deg(b.rng.uniform(-15.0, 25.0)), b.rng.uniform(0.2, 0.7), 0.0};
      p.trunk_pitch = b.rng.uniform(0.1, 0.3);
      phase = "reach_bench", hold = b.rng.uniform(0.5, 1.5);
    } else if (u < 0.35) {  // pick a part up low, then place it to the side
      p.trunk_pitch = b.rng.uniform(0.3, 0.6);
      arm = {deg(b.rng.uniform(30.0, 50.0)), deg(b.rng.uniform(-10.0, 20.0)), b.rng.uniform(0.1, 0.4), 0.0};
      b.to(p, b.rng.uniform(0.6, 1.0), "pick");
      b.hold(b.rng.uniform(0.3, 0.8), "pick");
      p.trunk_pitch = b.rng.uniform(0.1, 0.3);
      arm = {deg(b.rng.uniform(50.0, 75.0)), deg(b.rng.uniform(30.0, 70.0)), b.rng.uniform(0.3, 0.8), 0.0};
      phase = "place", hold = b.rng.uniform(0.3, 0.8);
    } else if (u < 0.47) {  // carry a part round: both forearms up, turning
      const ArmPose carry{deg(b.rng.uniform(20.0, 35.0)), 0.0, b.rng.uniform(1.2, 1.6), 0.0};
      p = with_arms(p, carry, carry);
      b.to(p, 0.7, "carry");
      p.heading += deg(b.rng.uniform(60.0, 120.0)) * (b.rng.chance(0.5) ? 1 : -1);
      b.to(p, b.rng.uniform(1.0, 1.8), "carry", true);
      b.hold(b.rng.uniform(0.3, 0.8), "carry");
      p = with_arms(p, arm_rest(), arm_rest());
      b.to(p, 0.6, "carry");
      p.heading = rest.heading;
      b.to(p, b.rng.uniform(1.0, 1.6), "turn_back", true);
      continue;
    } else if (u < 0.57) {  // turn to the robot, watch it, turn back
      p.heading += deg(b.rng.uniform(40.0, 80.0)) * (b.rng.chance(0.5) ? 1 : -1);
      b.to(p, b.rng.uniform(0.8, 1.2), "turn_to_robot", true);
      b.hold(b.rng.uniform(1.0, 2.5), "watch_robot");
      b.to(rest, b.rng.uniform(0.8, 1.2), "turn_back", true);
      continue;
    } else if (u < 0.67) {  // scratch the head
      arm = {deg(b.rng.uniform(130.0, 155.0)), deg(b.rng.uniform(40.0, 70.0)), b.rng.uniform(2.0, 2.4), 0.3};
      phase = "scratch_head", hold = b.rng.uniform(0.8, 2.0);
    } else if (u < 0.77) {  // adjust glasses
      arm = {deg(b.rng.uniform(45.0, 65.0)), deg(b.rng.uniform(-10.0, 10.0)), b.rng.uniform(2.3, 2.6), 0.6};
      phase = "glasses", hold = b.rng.uniform(0.4, 1.0);
    } else if (u < 0.87) {  // a tool from the shelf at the side: the arm straight out, held while the hand finds it
      arm = {deg(b.rng.uniform(80.0, 110.0)), deg(b.rng.uniform(45.0, 95.0)), b.rng.uniform(0.0, 0.25), 0.0};
      phase = "shelf", hold = b.rng.uniform(0.5, 1.2);
    } else {
      b.hold(b.rng.uniform(1.0, 3.0), "rest");
      continue;
    }
    b.to(p, b.rng.uniform(0.5, 0.9), phase);
    b.hold(hold, phase);
    b.to(rest, b.rng.uniform(0.5, 0.9), "rest");
  }
  b.hold(std::max(0.2, end - b.t), "rest");
}

// Pointing at the floor of the cell (the arm straight, 35-65 degrees from
// hanging down, so the ray meets the floor 1-3 m away), with either arm,
// between waves and overhead stretches that are not pointing. Phases:
// raise:SIDE, hold:SIDE, retract:SIDE for pointing; wave:SIDE, stretch:SIDE
// for the others; rest between.
void script_point(Builder& b, Rng& rng) {
  const BodyPose rest = b.cur;
  for (int i = 0; i < 10; ++i) {
    const bool right = rng.chance(0.5);
    const std::string side = right ? "right" : "left";
    const int kind = i % 5 == 2 ? 1 : i % 5 == 4 ? 2 : 0;  // 6 points, 2 waves, 2 stretches
    BodyPose p = rest;
    ArmPose& arm = right ? p.right_arm : p.left_arm;
    b.hold(rng.uniform(1.0, 2.5), "rest");
    if (kind == 0) {
      arm.elevation = deg(rng.uniform(35.0, 65.0));
      arm.azimuth = deg(rng.uniform(-20.0, 60.0));  // positive: out to that arm's side
      arm.elbow_flex = 0.05;
      b.to(p, rng.uniform(0.5, 1.3), "raise:" + side);
      b.hold(rng.uniform(0.8, 2.0), "hold:" + side);
      b.to(rest, rng.uniform(0.5, 1.2), "retract:" + side);
    } else if (kind == 1) {
      arm = {deg(rng.uniform(120.0, 150.0)), deg(rng.uniform(30.0, 70.0)), deg(40), 0.0};
      b.to(p, rng.uniform(0.5, 0.9), "wave:" + side);
      const int swings = 2 + static_cast<int>(rng.uniform(0.0, 3.0));
      for (int k = 0; k < 2 * swings; ++k) {
        BodyPose q = p;
        (right ? q.right_arm : q.left_arm).elbow_flex = deg(k % 2 ? 20.0 : 70.0);
        (right ? q.right_arm : q.left_arm).azimuth += deg(k % 2 ? -15.0 : 15.0);
        b.to(q, rng.uniform(0.2, 0.35), "wave:" + side);
      }
      b.to(rest, rng.uniform(0.5, 1.0), "wave:" + side);
    } else {
      arm = {deg(rng.uniform(160.0, 175.0)), deg(rng.uniform(0.0, 40.0)), 0.1, 0.0};
      b.to(p, rng.uniform(0.6, 1.2), "stretch:" + side);
      b.hold(rng.uniform(0.5, 1.0), "stretch:" + side);
      b.to(rest, rng.uniform(0.6, 1.2), "stretch:" + side);
    }
  }
  b.hold(1.0, "rest");
}

// robot: a worker at the origin facing an arm 1.9 m ahead (bringup/robot_cell.yaml's
// base), who walks up to it, reaches into its workspace, backs off, walks
// past in front of it and comes back. Phases: rest, approach, reach, leave,
// pass, return (the walking ones with a gait).
void script_robot(Builder& b) {
  const BodyPose rest = b.cur;
  const auto walk_to = [&](Eigen::Vector2d where, double speed, const std::string& phase, std::optional<double> heading = {}) {
    BodyPose p = b.cur;
    const double d = (where - p.floor_position).norm();
    p.heading = heading ? *heading : heading_towards(p.floor_position, where);
    b.to(p, 0.4, phase);
    p.floor_position = where;
    b.to(p, std::max(0.3, d / speed), phase, true);
  };
  b.hold(2.0, "rest");
  walk_to({0.0, b.rng.uniform(0.8, 0.95)}, b.rng.uniform(0.8, 1.2), "approach", rest.heading);
  const ArmPose reach{deg(b.rng.uniform(75.0, 95.0)), deg(b.rng.uniform(-10.0, 10.0)), b.rng.uniform(0.0, 0.3), 0.0};
  b.to(with_arms(b.cur, reach, reach), b.rng.uniform(0.6, 0.9), "reach");
  b.hold(b.rng.uniform(1.0, 2.0), "reach");
  b.to(with_arms(b.cur, arm_rest(), arm_rest()), 0.8, "reach");
  walk_to({0.0, -0.2}, 0.8, "leave", rest.heading);
  walk_to({-1.4, 0.9}, b.rng.uniform(1.0, 1.3), "pass");
  walk_to({1.4, b.rng.uniform(0.8, 1.1)}, b.rng.uniform(1.0, 1.5), "pass");
  walk_to({0.0, 0.0}, b.rng.uniform(1.0, 1.3), "return");
  BodyPose p = b.cur;
  p.heading = rest.heading;
  b.to(p, 0.8, "rest");
}

constexpr double kWalkRadius = 0.5;
// tour: a wider circle, facing where they go (a calibration walk: every sensor sees the front and the back).
constexpr double kTourRadius = 0.8;

// shift: where the places are, and the doors the people come through
// (outside every default sensor's view: on the diagonals, beyond 3 m).
constexpr double kPlaceRadius = 0.7, kDoorRadius = 3.6;

// A person at a place, facing the centre: reaching, holding, arms out,
// picking from low down and resting, for `work` seconds.
void script_work(Builder& b, double work) {
  const BodyPose rest = b.cur;
  const double end = b.t + work;
  while (b.t < end - 1.0) {
    const double u = b.rng.uniform();
    BodyPose p = rest;
    if (u < 0.3) {
      const ArmPose reach{deg(b.rng.uniform(60.0, 95.0)), deg(b.rng.uniform(-10.0, 15.0)), b.rng.uniform(0.1, 0.6), 0.0};
      p = with_arms(p, reach, reach);
      b.to(p, b.rng.uniform(0.6, 1.0), "reach");
      b.hold(b.rng.uniform(0.8, 2.0), "reach");
    } else if (u < 0.5) {
      const bool right = b.rng.chance(0.5);
      (right ? p.right_arm : p.left_arm) = {deg(b.rng.uniform(70.0, 100.0)), deg(b.rng.uniform(40.0, 90.0)), 0.1, 0.0};
      b.to(p, b.rng.uniform(0.6, 1.0), "hold_out");
      b.hold(b.rng.uniform(0.8, 2.0), "hold_out");
    } else if (u < 0.65) {
      p.trunk_pitch = b.rng.uniform(0.4, 0.7);
      const ArmPose low{b.rng.uniform(0.6, 0.9), 0.1, 0.2, 0.0};
      p = with_arms(p, low, low);
      b.to(p, b.rng.uniform(0.8, 1.2), "pick");
      b.hold(b.rng.uniform(0.5, 1.0), "pick");
    } else {
      b.hold(b.rng.uniform(1.0, 3.0), "rest");
      continue;
    }
    b.to(rest, b.rng.uniform(0.6, 1.0), "rest");
  }
  b.hold(std::max(0.2, end - b.t), "rest");
}

}  // namespace

ArmPose arm_rest() { return {0.08, kPi / 2, 0.1, 0.0}; }
ArmPose arm_side() { return {kPi / 2, kPi / 2, 0.0, 0.0}; }
ArmPose arm_forward() { return {kPi / 2, 0.0, 0.0, 0.0}; }
ArmPose arm_behind_back() { return {0.55, kPi, kPi / 2, kPi / 2}; }

BodyPose interpolate(const BodyPose& a, const BodyPose& b, double u) {
  BodyPose p;
  p.floor_position = a.floor_position + (b.floor_position - a.floor_position) * u;
  p.heading = lerp(a.heading, b.heading, u);
  p.pelvis_drop = lerp(a.pelvis_drop, b.pelvis_drop, u);
  p.trunk_pitch = lerp(a.trunk_pitch, b.trunk_pitch, u);
  p.left_arm = lerp(a.left_arm, b.left_arm, u);
  p.right_arm = lerp(a.right_arm, b.right_arm, u);
  p.left_leg = lerp(a.left_leg, b.left_leg, u);
  p.right_leg = lerp(a.right_leg, b.right_leg, u);
  return p;
}

const std::vector<std::string>& scenario_names() {
  static const std::vector<std::string> names{"walk", "360",   "hide",  "box",  "occ",  "sit",
                                              "arms", "point", "shift", "tour", "robot", "work"};
  return names;
}

Scenario::Scenario(const ScenarioOptions& options) : opt_(options) {
  if (std::find(scenario_names().begin(), scenario_names().end(), opt_.name) == scenario_names().end()) {
    std::string all;
    for (const auto& n : scenario_names()) all += (all.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown scenario '" + opt_.name + "' (expected one of: " + all + ")");
  }
  if (opt_.repeats < 1 || opt_.repeats > 1000) throw std::invalid_argument("scenario repeats must be 1-1000");
  if (opt_.people < 1 || opt_.people > 8) throw std::invalid_argument("scenario people must be 1-8");

  if (!(opt_.work_s > 0.0 && opt_.work_s <= 3600.0)) throw std::invalid_argument("scenario work time must be 0-3600 s");

  Rng rng = Rng(opt_.seed).fork(0x5ce7a210);
  const BodyPose start = standing(heading_towards({0.0, 0.0}, opt_.facing));
  keys_.push_back({0.0, start, "stand", false});
  if (opt_.name == "shift") {
    plan_shift(rng);
    return;
  }
  Builder b{rng, keys_, start};
  const double hip_height = BodyDimensions::from_height(opt_.height).hip_height;
  for (int r = 0; r < opt_.repeats; ++r) {
    const auto& n = opt_.name;
    if (n == "walk" || n == "tour") {
      const double lap = b.vary(20.0);
      walk_period_ = walk_period_ == 0.0 ? lap : walk_period_;
      b.t += walk_period_;
      keys_.push_back({b.t, start, "walk", false});
    } else if (n == "360") {
      script_360(b);
    } else if (n == "hide") {
      script_hide(b);
    } else if (n == "box") {
      script_box(b, BodyDimensions::from_height(opt_.height));
    } else if (n == "occ") {
      script_occ(b);
    } else if (n == "sit") {
      script_sit(b, hip_height);
    } else if (n == "arms") {
      script_arms(b);
    } else if (n == "robot") {
      script_robot(b);
    } else if (n == "work") {
      script_work_cell(b);
    } else {
      script_point(b, rng);
    }
  }
  duration_ = keys_.back().t;
}

void Scenario::plan_shift(Rng& rng) {
  const int places = opt_.people;
  std::vector<Visit> visits;
  for (int k = 0; k < places; ++k) {
    const double a = kPi / 4 + 2 * kPi * k / places;
    const Eigen::Vector2d dir(std::sin(a), std::cos(a));
    const Eigen::Vector2d door = kDoorRadius * dir, place = kPlaceRadius * dir;
    double t = rng.uniform(0.0, 6.0) + 2.0 * k;
    for (int r = 0; r < opt_.repeats; ++r) {
      Visit v;
      v.slot = static_cast<std::size_t>(k);
      v.enter = t;
      const double speed = rng.uniform(1.0, 1.4);
      const double walk = (door - place).norm() / speed;
      BodyPose p = standing(heading_towards(door, place));
      p.floor_position = door;
      Builder b{rng, v.keys, p};
      b.t = t;
      v.keys.push_back({t, p, "walk_in", false});
      p.floor_position = place;
      b.cur = p;
      b.t += walk;
      v.keys.push_back({b.t, p, "walk_in", true});
      script_work(b, rng.uniform(0.5, 1.5) * opt_.work_s);
      p = b.cur;
      p.heading += kPi;
      b.to(p, 0.8, "turn");
      p.floor_position = door;
      b.cur = p;
      b.t += walk;
      v.keys.push_back({b.t, p, "walk_out", true});
      v.leave = b.t;
      visits.push_back(std::move(v));
      t = b.t + rng.uniform(2.0, 8.0);
    }
  }
  std::sort(visits.begin(), visits.end(), [](const Visit& x, const Visit& y) { return x.enter < y.enter; });
  for (std::size_t i = 0; i < visits.size(); ++i) visits[i].person_id = static_cast<std::uint32_t>(i + 1);
  // The cell stays empty a while at the end, so that every departure can be seen.
  for (const auto& v : visits) duration_ = std::max(duration_, v.leave + 6.0);
  visits_ = std::move(visits);
}

namespace {
// The pose at t along keys (clamped to their span), eased or linear per
// segment; `blended`: between two keys rather than at an end.
BodyPose pose_on(const std::vector<Scenario::Key>& keys, double t, std::string* phase, bool* blended) {
  *blended = false;
  const auto it = std::upper_bound(keys.begin(), keys.end(), t, [](double v, const Scenario::Key& k) { return v < k.t; });
  if (it == keys.begin()) {
    *phase = keys.front().phase;
    return keys.front().pose;
  }
  if (it == keys.end()) {
    *phase = keys.back().phase;
    return keys.back().pose;
  }
  const auto& k0 = *(it - 1);
  const auto& k1 = *it;
  const double span = k1.t - k0.t;
  double u = span > 0 ? (t - k0.t) / span : 1.0;
  if (!k1.linear) u = smoothstep(u);
  *phase = k1.phase;
  *blended = true;
  return interpolate(k0.pose, k1.pose, u);
}
}  // namespace

BodyPose Scenario::script_pose(double t, std::string* phase) const {
  bool blended = false;
  BodyPose p = pose_on(keys_, t, phase, &blended);
  if (!blended) return p;
  // Keyframes keep the feet on the floor; blends between them must too.
  const auto d = BodyDimensions::from_height(opt_.height);
  for (const auto* leg : {&p.left_leg, &p.right_leg}) {
    p.pelvis_drop = std::min(p.pelvis_drop, crouch_drop(d, *leg));
  }
  return p;
}

std::vector<Obstacle> Scenario::props(double t, const BodyPose& first) const {
  std::vector<Obstacle> out;
  if (opt_.name == "occ") {
    // A partition 1.3 m wide and 2 m high between sensor 1 and the hiding place.
    out.push_back({"wall", Eigen::AlignedBox3d(Eigen::Vector3d(-1.8, 0.0, 0.55), Eigen::Vector3d(-0.5, 2.0, 0.65))});
  } else if (opt_.name == "sit") {
    const Eigen::Vector3d c(first.floor_position.x(), 0.0, first.floor_position.y());
    out.push_back({"chair", Eigen::AlignedBox3d(c + Eigen::Vector3d(-0.23, 0.0, -0.28), c + Eigen::Vector3d(0.23, 0.47, 0.17))});
    out.push_back({"chair", Eigen::AlignedBox3d(c + Eigen::Vector3d(-0.23, 0.47, -0.31), c + Eigen::Vector3d(0.23, 0.95, -0.26))});
  } else if (opt_.name == "box") {
    std::string phase;
    script_pose(t, &phase);
    const Eigen::Vector3d half(0.15, 0.10, 0.12);  // a 30 x 20 x 24 cm box
    Eigen::Vector3d centre;
    if (phase == "lift" || phase == "hold_out" || phase == "lower") {
      const auto s = forward_kinematics(BodyDimensions::from_height(opt_.height), first);
      centre = 0.5 * (s[skeleton::JointId::LeftHand].position + s[skeleton::JointId::RightHand].position);
      const Eigen::Vector3d fwd(std::sin(first.heading), 0.0, std::cos(first.heading));
      // The hands grip its sides near the top, a little behind its middle.
      centre += 0.04 * fwd - Eigen::Vector3d(0.0, 0.08, 0.0);
    } else {
      const Eigen::Vector3d fwd(std::sin(first.heading), 0.0, std::cos(first.heading));
      centre = Eigen::Vector3d(first.floor_position.x(), half.y(), first.floor_position.y()) + 0.40 * fwd;
    }
    out.push_back({"box", Eigen::AlignedBox3d(centre - half, centre + half)});
  }
  return out;
}

Scene Scenario::at(double t) const {
  t = std::clamp(t, 0.0, duration_);
  Scene scene;
  scene.t = t;
  if (opt_.name == "shift") {
    for (const auto& v : visits_) {
      if (t < v.enter || t >= v.leave) continue;
      Actor a;
      a.person_id = v.person_id;
      a.slot = v.slot;
      bool blended = false;
      a.pose = pose_on(v.keys, t, &a.phase, &blended);
      if (a.phase == "walk_in" || a.phase == "walk_out") gait(a.pose, 2 * kPi * 0.9 * t + static_cast<double>(v.slot));
      scene.actors.push_back(a);
    }
    return scene;
  }
  Actor first;
  first.person_id = 1;
  first.pose = script_pose(t, &first.phase);
  if (opt_.name == "walk") {
    const double a = 2 * kPi * t / walk_period_;
    first.pose.floor_position = kWalkRadius * Eigen::Vector2d(std::sin(a), -std::cos(a));
    first.pose.heading = heading_towards(first.pose.floor_position, opt_.facing);
    gait(first.pose, 2 * kPi * 0.9 * t);
  } else if (opt_.name == "tour") {
    const double a = 2 * kPi * t / walk_period_;
    first.pose.floor_position = kTourRadius * Eigen::Vector2d(std::sin(a), -std::cos(a));
    first.pose.heading = heading_towards(first.pose.floor_position,
                                         first.pose.floor_position + Eigen::Vector2d(std::cos(a), std::sin(a)));
    gait(first.pose, 2 * kPi * 0.9 * t);
    first.phase = "walk";
  } else if (opt_.name == "robot" && first.phase != "rest" && first.phase != "reach") {
    gait(first.pose, 2 * kPi * 0.9 * t);
  }
  scene.actors.push_back(first);
  // Others walk a wide circle through the cell, facing where they go.
  for (int k = 1; k < opt_.people; ++k) {
    Actor a;
    a.person_id = static_cast<std::uint32_t>(k + 1);
    a.slot = static_cast<std::size_t>(k);
    const double angle = 2 * kPi * (t / 20.0 + static_cast<double>(k) / opt_.people) + 0.3;
    a.pose = standing();
    a.pose.floor_position = 1.3 * Eigen::Vector2d(std::sin(angle), std::cos(angle));
    a.pose.heading = angle + kPi / 2;
    gait(a.pose, 2 * kPi * 0.9 * t + k);
    a.phase = "walk";
    scene.actors.push_back(a);
  }
  scene.obstacles = props(t, first.pose);
  return scene;
}

}  // namespace skelgraph::sim
