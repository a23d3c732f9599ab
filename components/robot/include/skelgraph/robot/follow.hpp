#pragma once
// Following a worker's hand (the source thesis's second demonstration),
// DDS-free: from the fused people, where the robot's tool should go. The
// tool keeps `standoff_m` from the hand, on the robot's side of it
// (horizontally towards the base), inside a workspace box; it holds where it
// is when there is no hand to follow (nobody, the hand not tracked, the data
// too old). One person is followed while they are there; then the one whose
// hand is nearest the workspace. Speed and separation monitoring still
// decides how fast (or whether) the robot moves: a standoff beyond S_p lets
// it follow at speed. Time passed in.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::robot {

struct FollowParams {
  skeleton::JointId joint = skeleton::JointId::RightHand;
  double standoff_m = 0.8;
  Eigen::AlignedBox3d workspace{Eigen::Vector3d(-0.7, 0.2, 1.0), Eigen::Vector3d(0.7, 1.6, 1.9)};  // world, m
  double max_age_s = 0.25;  // fused data older than this (now minus its newest capture): hold
};

struct FollowTarget {
  bool hold = true;  // no hand to follow: stay where it is
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // tool, world (when not holding)
  std::uint32_t person = 0;                          // who is followed (0: nobody)
  std::string reason;                                // why it holds, or "following person N"
};

class Follower {
 public:
  Follower(FollowParams params, Eigen::Vector3d robot_base_world);
  // The target for the fused people at now_ns (their capture stamps on the same clock).
  FollowTarget step(const std::vector<skeleton::Skeleton>& people, std::int64_t now_ns);
  const FollowParams& params() const { return p_; }

 private:
  FollowParams p_;
  Eigen::Vector3d base_;
  std::optional<std::uint32_t> followed_;
};

}  // namespace skelgraph::robot
