#pragma once
// `separation` component: speed-and-separation monitoring of one robot
// (separation.hpp; not a certified safety function). Fused skeletons, the
// robot's state and the sensors' frame heartbeats in; every 1/rate_hz the
// closest person part to the closest robot part, S_p with the measured
// reaction time (the people data's age from the fused skeletons' capture
// stamps, plus compute and command latency), and a verdict: RUN, REDUCED (a
// speed scale) or PROTECTIVE_STOP, published on skelgraph/safety (on change
// and every 100 ms) and commanded on skelgraph/robot/command.

#include <cstdint>
#include <map>
#include <string>

#include "skelgraph/robot/separation.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/rate_stats.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::robot {

class SeparationComponent final : public runtime::Component {
 public:
  SeparationComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void step();
  void command(msg::RobotCommandKind kind, double value);

  std::string robot_id_;
  SeparationParams params_;
  StoppingModel stopping_;
  double rate_hz_, robot_max_speed_, command_latency_s_, person_timeout_s_, sensor_timeout_s_;
  int min_sensors_;
  struct Person {
    skeleton::Skeleton s;
    std::int64_t received_ns = 0;
  };
  std::map<std::uint32_t, Person> people_;
  std::map<std::string, std::int64_t> sensor_seen_ns_;  // last frame heartbeat per sensor
  bool have_robot_ = false;
  msg::RobotState robot_;
  std::int64_t robot_received_ns_ = 0;
  StopLatch latch_;
  SafetyDecision last_;
  bool published_once_ = false;
  std::int64_t last_publish_ns_ = 0;
  double last_compute_s_ = 0;
  std::map<std::string, std::uint64_t> time_in_;  // steps per state
  std::uint64_t steps_ = 0, stops_ = 0, commands_ = 0, failed_writes_ = 0;
  runtime::Percentiles reaction_ms_;
  runtime::Publisher<msg::SafetyStatus> safety_pub_;
  runtime::Publisher<msg::RobotCommand> command_pub_;
  std::string stop_label_;      // before the subscriptions: their callbacks read them
  double gesture_stop_s_ = 5.0;
  std::int64_t gesture_stop_until_ns_ = 0;  // a stop gesture holds the robot until then
  std::string gesture_stop_reason_;
  std::uint64_t stop_gestures_ = 0;
  runtime::Subscription<msg::Skeleton> fused_sub_;
  runtime::Subscription<msg::RobotState> robot_sub_;
  runtime::Subscription<msg::SensorFrame> frame_sub_;
  runtime::Subscription<msg::GestureEvent> gesture_sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::robot
