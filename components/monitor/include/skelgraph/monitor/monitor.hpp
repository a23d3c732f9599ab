#pragma once
// `monitor` component: listens to the sync topics and component status and
// reports what it saw (the demo prints this).

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "skelgraph/monitor/sync_watch.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::monitor {

class Monitor final : public runtime::Component {
 public:
  Monitor(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  std::string summary() const override;
  // Sessions (START/STOP, ticks, gaps, rate) and the last status of each component.
  nlohmann::json details() const override;

 private:
  void on_command(const msg::SyncCommand& c, std::int64_t receive_ns);

  SyncWatch watch_;
  std::map<std::string, msg::ComponentStatus> status_;  // by component name
  runtime::Subscription<msg::SyncCommand> sync_sub_;
  runtime::Subscription<msg::SyncCommand> session_sub_;  // START even if it came before we matched
  std::unique_ptr<runtime::Subscription<msg::ComponentStatus>> status_sub_;
};

}  // namespace skelgraph::monitor
