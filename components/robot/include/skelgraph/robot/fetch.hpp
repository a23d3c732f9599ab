#pragma once
// Pointing to fetch, DDS-free: a worker points at a spot on the floor; if
// the robot can reach it, its tool goes to hover above it (the robot would
// pick something up there). Only while the separation monitor says RUN (the
// caller checks). The tool's own motion is the arm's (ArmSim or a robot).

#include <optional>

#include <Eigen/Core>

namespace skelgraph::robot {

struct FetchParams {
  double hover_m = 0.15;      // above the pointed spot
  double min_reach_m = 0.25;  // horizontally from the base: closer is the robot's own footprint
  double max_reach_m = 0.8;   // ... farther is out of reach (a UR5e reaches 0.85 m)
};

// The tool target for a pointed floor spot (world, y up), or none when the
// spot is out of the robot's reach from its base.
std::optional<Eigen::Vector3d> fetch_target(const Eigen::Vector3d& floor_spot, const Eigen::Vector3d& base_world,
                                            const FetchParams& p = {});

}  // namespace skelgraph::robot
