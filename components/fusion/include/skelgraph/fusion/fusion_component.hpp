#pragma once
// `fusion` component: raw skeletons of every sensor in, one fused skeleton per
// person out on skelgraph/skeleton/fused, at a fixed rate or on every sync
// TICK while a session runs. Sensor poses come from skelgraph/calibration
// (transient-local, so late joiners get them). A sensor silent for longer than
// the timeout (no skeletons and no frames on skelgraph/sensor/frame) makes
// the status DEGRADED; fusion goes on with the rest and takes
// the sensor back when it returns. A raw skeleton instance its source
// disposes (the tracker lost the person) ends that stream at once; a fused
// person with no stream left, or none for person_timeout_ms, is disposed on
// skelgraph/skeleton/fused. The Fuser core does the work.

#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "skelgraph/fusion/arrival_gate.hpp"
#include "skelgraph/fusion/fuser.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/rate_stats.hpp"

namespace skelgraph::fusion {

class FusionComponent final : public runtime::Component {
 public:
  FusionComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void step(std::int64_t now_ns);
  void fuse_if_ready(std::int64_t now_ns);
  void update_health(std::int64_t now_ns);

  Fuser fuser_;
  std::string output_id_;
  std::int64_t period_ns_;
  std::string trigger_;            // ticks, timer or arrival
  ArrivalGate gate_;
  runtime::TimerHandle wait_timer_;  // arrival: ends the wait for the other sensors
  bool wait_armed_ = false;
  std::int64_t last_tick_ns_ = 0;  // when the last sync TICK drove a step
  std::int64_t last_step_ns_ = 0;
  runtime::Percentiles compute_;   // fuse() per step, microseconds
  std::uint64_t steps_ = 0, published_ = 0, tick_steps_ = 0, departed_ = 0;
  std::set<std::string> silent_;
  std::uint64_t dropouts_ = 0, rejoins_ = 0;
  runtime::Publisher<msg::Skeleton> out_;
  runtime::Subscription<msg::Skeleton> raw_sub_;
  runtime::Subscription<msg::SensorFrame> frame_sub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Subscription<msg::SyncCommand> sync_sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::fusion
