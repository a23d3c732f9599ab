#include "skelgraph/robot/fetch.hpp"

#include <Eigen/Geometry>

namespace skelgraph::robot {

std::optional<Eigen::Vector3d> fetch_target(const Eigen::Vector3d& floor_spot, const Eigen::Vector3d& base_world,
                                            const FetchParams& p) {
  Eigen::Vector3d d = floor_spot - base_world;
  d.y() = 0;
  const double r = d.norm();
  if (r < p.min_reach_m || r > p.max_reach_m) return std::nullopt;
  return Eigen::Vector3d(floor_spot.x(), floor_spot.y() + p.hover_m, floor_spot.z());
}

}  // namespace skelgraph::robot
