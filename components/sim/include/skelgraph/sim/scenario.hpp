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

// An opaque axis-aligned prop: kind is "wall", "box" or "chair".
struct Obstacle {
  std::string kind;
  Eigen::AlignedBox3d box;
};

struct Actor {
  std::uint32_t person_id = 1;
  BodyPose pose;
  std::string phase;  // what they are doing, e.g. "turn", "hide_left", "raise:right" (labels for gesture tools)
};

struct Scene {
  double t = 0.0;  // s since the start of the scenario
  std::vector<Actor> actors;
  std::vector<Obstacle> obstacles;
};

struct ScenarioOptions {
  std::string name = "walk";
  std::uint64_t seed = 1;
  int repeats = 1;   // the script is performed this many times in a row
  int people = 1;    // people beyond the first walk around the cell, crossing the sensors' views
  double height = 1.75;  // of every person, m
  // Floor point (x, z) the first person faces (sensor 1). The cell centre is the origin.
  Eigen::Vector2d facing{0.0, 2.0};
};

// walk, 360, hide, box, occ, sit, arms, point.
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

 private:
  BodyPose script_pose(double t, std::string* phase) const;
  std::vector<Obstacle> props(double t, const BodyPose& first) const;

  ScenarioOptions opt_;
  std::vector<Key> keys_;
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
