#pragma once
// `follow` component: the robot's tool follows a worker's hand (follow.hpp).
// Fused skeletons in; every 1/rate_hz a target from the Follower, sent on
// skelgraph/robot/command as ROBOT_MOVE_TO (when it moved by min_move_m or
// more) or ROBOT_HOLD (when there is no hand to follow). The `separation`
// monitor still decides how fast, or whether, the robot moves.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "skelgraph/robot/follow.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::robot {

class FollowComponent final : public runtime::Component {
 public:
  FollowComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void step();
  void command(msg::RobotCommandKind kind, const Eigen::Vector3d& target);

  std::string robot_id_;
  double rate_hz_, speed_, min_move_m_, person_timeout_s_;
  Follower follower_;
  std::map<std::uint32_t, std::pair<skeleton::Skeleton, std::int64_t>> people_;  // with when received
  std::optional<Eigen::Vector3d> sent_;  // the last target sent (none: holding)
  bool sent_once_ = false;
  std::string reason_;
  std::uint64_t steps_ = 0, following_ = 0, moves_ = 0, holds_ = 0, failed_writes_ = 0;
  runtime::Publisher<msg::RobotCommand> command_pub_;
  runtime::Subscription<msg::Skeleton> fused_sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::robot
