#pragma once
// `fetch` component: pointing to fetch (fetch.hpp). Gesture events in; a
// pointing event (label `label`) whose floor target the robot reaches, while
// the robot's monitor says RUN (its latest verdict on skelgraph/safety, at
// most `max_verdict_age_ms` old; or REDUCED with `allow_reduced`), sends the tool to hover above the target
// (ROBOT_MOVE_TO on skelgraph/robot/command). A held gesture repeats its
// event: the same target (within 5 cm) is sent once.

#include <cstdint>
#include <optional>
#include <string>

#include "skelgraph/robot/fetch.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::robot {

class FetchComponent final : public runtime::Component {
 public:
  FetchComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void on_event(const msg::GestureEvent& e);

  std::string robot_id_, label_;
  Eigen::Vector3d base_;
  FetchParams params_;
  double speed_;
  std::int64_t max_verdict_age_ns_;
  bool allow_reduced_;
  std::optional<msg::SafetyStatus> verdict_;
  std::int64_t verdict_ns_ = 0;
  std::optional<Eigen::Vector3d> sent_;
  std::uint64_t events_ = 0, out_of_reach_ = 0, not_run_ = 0, sent_count_ = 0, repeats_ = 0, failed_writes_ = 0;
  std::string last_;
  runtime::Publisher<msg::RobotCommand> command_pub_;
  runtime::Subscription<msg::SafetyStatus> safety_sub_;
  runtime::Subscription<msg::GestureEvent> gesture_sub_;
};

}  // namespace skelgraph::robot
