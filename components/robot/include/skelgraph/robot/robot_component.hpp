#pragma once
// `robot` component: the simulated arm (ArmSim) in the cell. Publishes its
// state on skelgraph/robot/state at `rate_hz` (joints, tool, speed scale,
// stop, capsules in the world) and obeys skelgraph/robot/command (move the
// tool to a target, hold, speed scale, protective stop, resume) when it comes
// from a source it takes and is fresh (CommandGate; refusals on its status).
// Its state is its truth: recorded like the people's.

#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/robot/arm.hpp"
#include "skelgraph/robot/command_gate.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::robot {

class RobotComponent final : public runtime::Component {
 public:
  RobotComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void on_command(const msg::RobotCommand& c);
  void step();

  std::string id_;
  ArmSim arm_;
  // A task of its own: the tool round these points (world) at task_speed, each
  // next one when the last is reached, until a command takes over.
  std::vector<Eigen::Vector3d> task_;
  std::size_t task_next_ = 0;
  bool task_active_ = false;
  std::uint64_t task_points_reached_ = 0;
  double rate_hz_;
  double task_speed_ = 0.5;
  std::int64_t last_mono_ns_ = 0;
  std::uint64_t steps_ = 0, commands_ = 0, stops_ = 0, ignored_ = 0, published_ = 0, failed_publish_ = 0;
  CommandGate gate_;
  std::uint64_t refused_source_ = 0, refused_stale_ = 0;
  std::string last_refusal_;
  runtime::Publisher<msg::RobotState> state_pub_;
  runtime::Subscription<msg::RobotCommand> command_sub_;
  runtime::TimerHandle timer_;
};

// "x,y,z,yaw_deg" -> base pose; "j1,...,j6" degrees -> joints; "x,y,z" -> a point.
// Throw std::invalid_argument naming what is wrong.
Eigen::Isometry3d parse_base(const std::string& text);
Eigen::Vector3d parse_point(const std::string& text);
Joints parse_joints_deg(const std::string& text);
// The state message of an arm.
msg::RobotState state_msg(const std::string& robot_id, const ArmSim& arm, std::int64_t stamp_ns);
// A command to a robot (the one message every commanding component sends).
msg::RobotCommand command_msg(const std::string& robot_id, msg::RobotCommandKind kind, double value,
                              const Eigen::Vector3d& target, const std::string& source, std::int64_t stamp_ns);

}  // namespace skelgraph::robot
