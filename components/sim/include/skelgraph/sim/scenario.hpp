#pragma once
// Scripted, seeded, deterministic scenarios: what each person in the work cell
// does over time, and the props (wall, box, chair) that can hide them. The
// seed varies timings (and the pointing targets); the same seed gives the same
// motion. DDS-free.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/sim/body.hpp"

namespace skelgraph::sim {

class Rng;

// An opaque axis-aligned prop: kind is "wall", "box" or "chair".
struct Obstacle {
  std::string kind;
  Eigen::AlignedBox3d box;
};

struct Actor {
  std::uint32_t person_id = 1;
  BodyPose pose;
  std::string phase;  // what they are doing, e.g. "turn", "hide_left", "raise:right" (labels for gesture tools)
  std::size_t slot = 0;  // the place in the cell (one tracker per sensor and place); people in turn take a place
};

// One body segment: the points within `radius` of the segment a-b.
struct Capsule {
  Eigen::Vector3d a, b;
  double radius = 0.05;
};

struct Scene {
  double t = 0.0;  // s since the start of the scenario
  std::vector<Actor> actors;
  std::vector<Obstacle> obstacles;
  // Things that move and hide people but are none (a robot's links, world
  // frame): set from outside the scenario (Simulation::set_occluders).
  std::vector<Capsule> occluders;
};

struct ScenarioOptions {
  std::string name = "walk";
  std::uint64_t seed = 1;
  int repeats = 1;   // the script is performed this many times in a row (shift: people per place)
  int people = 1;    // people beyond the first walk around the cell, crossing the sensors' views
                     // (shift: places in the cell, each taken by one person after another)
  double height = 1.75;  // of every person, m
  double work_s = 20.0;  // shift: mean time a person works at a place (each 0.5-1.5 times it)
  // Floor point (x, z) the first person faces (sensor 1). The cell centre is the origin.
  Eigen::Vector2d facing{0.0, 2.0};
};

// walk, 360, hide, box, occ, sit, arms, point, shift, tour, robot.
//
// robot: a worker facing an arm 1.9 m ahead walks up to it, reaches into its
// workspace, backs off, walks past in front of it and comes back (with
// `people` 2, a second worker walks a 1.3 m circle through the arm's reach).
//
// shift: a working day in the cell. `people` places around the cell centre
// are each taken by `repeats` people in turn (people * repeats different
// people, ids 1, 2, ... in order of arrival): each walks in from outside every
// sensor's view, works at the place (reaching, holding, arms out, resting;
// 10-30 s), walks out the way they came and leaves the scene, and the next
// one comes a few seconds later.
const std::vector<std::string>& scenario_names();

class Scenario {
 public:
  // Throws std::invalid_argument for an unknown name or a bad count.
  explicit Scenario(const ScenarioOptions& options);

  const ScenarioOptions& options() const { return opt_; }
  double duration() const { return duration_; }
  // The scene at time t (clamped to [0, duration]).
  Scene at(double t) const;

  struct Key {
    double t;           // when the pose is reached
    BodyPose pose;
    std::string phase;  // phase of the segment ending at this key
    bool linear;        // constant-speed segment (turning), else eased
  };
  // shift: one person's time in the cell.
  struct Visit {
    std::uint32_t person_id = 0;
    std::size_t slot = 0;
    double enter = 0.0, leave = 0.0;  // in the scene from `enter` until `leave`
    std::vector<Key> keys;            // from the door, in, working, out to the door
  };
  const std::vector<Visit>& visits() const { return visits_; }

 private:
  BodyPose script_pose(double t, std::string* phase) const;
  void plan_shift(Rng& rng);
  std::vector<Obstacle> props(double t, const BodyPose& first) const;

  ScenarioOptions opt_;
  std::vector<Key> keys_;
  std::vector<Visit> visits_;  // shift
  double duration_ = 0.0;
  double walk_period_ = 0.0;  // walk: seconds per lap
};

// Handy poses, also used by tests.
ArmPose arm_rest();
ArmPose arm_side();      // horizontal, out to the side (T-pose)
ArmPose arm_forward();   // horizontal, straight ahead
ArmPose arm_behind_back();
BodyPose interpolate(const BodyPose& a, const BodyPose& b, double u);

}  // namespace skelgraph::sim
