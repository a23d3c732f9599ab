#pragma once
// Capsules (a segment swept by a sphere) and the distances between them: the
// shape model of the robot's links and of a person's body parts.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace skelgraph::robot {

struct Capsule {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  std::string name;  // e.g. "forearm", "right_hand"
};

// Closest points of segments [p0, p1] and [q0, q1]: their distance.
double segment_distance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                        const Eigen::Vector3d& q1);
// Surface to surface (negative: they overlap).
double capsule_distance(const Capsule& x, const Capsule& y);

struct ClosestPair {
  double distance = 0.0;  // surface to surface; +inf when either set is empty
  std::size_t first = 0, second = 0;  // indexes into the two sets
};
ClosestPair closest(const std::vector<Capsule>& xs, const std::vector<Capsule>& ys);

}  // namespace skelgraph::robot
