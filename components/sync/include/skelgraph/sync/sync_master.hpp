#pragma once
// `sync_master` component: publishes START / TICK / STOP on skelgraph/sync and
// the session state on skelgraph/sync/session; obeys skelgraph/sync/control;
// estimates each host's clock offset from the acks on skelgraph/sync_ack and
// publishes it on skelgraph/sync/clock (about once a second per host).

#include <map>
#include <optional>
#include <memory>
#include <string>

#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/sync/clock_offset.hpp"
#include "skelgraph/sync/sync_master_core.hpp"

namespace skelgraph::sync {

class SyncMaster final : public runtime::Component {
 public:
  SyncMaster(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();

  void on_start() override;
  void on_shutdown() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void start_session(const std::string& label, const std::string& request_id);
  void publish(const std::vector<SyncEvent>& events);
  void on_control(const msg::SyncControl& c);
  void on_ack(const msg::SyncAck& a, const runtime::SampleMeta& m);
  std::int64_t mono_ns() const;

  SyncMasterCore core_;
  bool autostart_;
  std::string label_;
  std::string last_request_id_;  // the control request last handled
  runtime::Publisher<msg::SyncCommand> sync_pub_;
  runtime::Publisher<msg::SyncCommand> session_pub_;
  runtime::Subscription<msg::SyncControl> control_sub_;
  runtime::Subscription<msg::SyncAck> ack_sub_;
  runtime::Publisher<msg::ClockOffset> clock_pub_;
  struct HostClock {
    ClockOffsetEstimator estimator;
    std::int64_t published_ns = 0;
    std::optional<ClockEstimate> last;
  };
  std::map<std::string, HostClock> clocks_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::sync
