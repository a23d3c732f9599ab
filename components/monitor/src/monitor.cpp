#include "skelgraph/monitor/monitor.hpp"

#include <cstdio>

#include "skelgraph/msg/json.hpp"

namespace skelgraph::monitor {

runtime::ComponentInfo Monitor::describe() {
  runtime::ComponentInfo info{"monitor", "Watches the sync topic and component status and reports what it saw", {}};
  info.params.add_bool("watch_status", true, "also collect ComponentStatus from skelgraph/status");
  return info;
}

Monitor::Monitor(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      sync_sub_(ctx, runtime::topics::kSync,
                [this](const msg::SyncCommand& c, const runtime::SampleMeta& m) { on_command(c, m.receive_ns); }),
      session_sub_(ctx, runtime::topics::kSyncSession,
                   [this](const msg::SyncCommand& c, const runtime::SampleMeta& m) { on_command(c, m.receive_ns); }) {
  if (params.get<bool>("watch_status")) {
    status_sub_ = std::make_unique<runtime::Subscription<msg::ComponentStatus>>(
        ctx, runtime::topics::kStatus,
        [this](const msg::ComponentStatus& s, const runtime::SampleMeta&) { status_[s.component_name().to_string()] = s; });
  }
}

void Monitor::on_command(const msg::SyncCommand& c, std::int64_t receive_ns) {
  const auto kind = c.kind() == msg::SYNC_START  ? SyncWatch::Kind::Start
                    : c.kind() == msg::SYNC_STOP ? SyncWatch::Kind::Stop
                                                 : SyncWatch::Kind::Tick;
  watch_.on_command(kind, c.session_id(), c.label().to_string(), c.tick(), c.master_stamp_ns(), receive_ns);
}

nlohmann::json Monitor::details() const {
  nlohmann::json sessions = nlohmann::json::array();
  for (const auto& s : watch_.sessions()) {
    sessions.push_back({{"session_id", s.session_id},
                        {"label", s.label},
                        {"saw_start", s.saw_start},
                        {"saw_stop", s.saw_stop},
                        {"ticks", s.ticks},
                        {"first_tick", s.first_tick},
                        {"last_tick", s.last_tick},
                        {"missing_ticks", s.missing_ticks},
                        {"stop_tick", s.stop_tick},
                        {"tick_rate_hz", s.master_rate_hz},
                        {"arrival_rate_hz", s.arrival.rate_hz},
                        {"arrival_period_min_ms", s.arrival.min_period_s * 1e3},
                        {"arrival_period_max_ms", s.arrival.max_period_s * 1e3},
                        {"arrival_period_std_ms", s.arrival.std_period_s * 1e3}});
  }
  nlohmann::json status = nlohmann::json::object();
  for (const auto& [name, s] : status_) status[name] = s;
  return {{"sessions", sessions}, {"status", status}};
}

std::string Monitor::summary() const {
  std::string out;
  for (const auto& s : watch_.sessions()) {
    char line[256];
    std::snprintf(line, sizeof(line), "%ssession %u '%s': %s%llu ticks at %.1f Hz (arrival period %.1f-%.1f ms)%s%s",
                  out.empty() ? "" : "; ", s.session_id, s.label.c_str(), s.saw_start ? "START, " : "",
                  static_cast<unsigned long long>(s.ticks), s.master_rate_hz, s.arrival.min_period_s * 1e3,
                  s.arrival.max_period_s * 1e3, s.missing_ticks > 0 ? ", gaps" : "", s.saw_stop ? ", STOP" : "");
    out += line;
  }
  if (out.empty()) out = "no sync traffic seen";
  out += "; status from " + std::to_string(status_.size()) + " component(s)";
  return out;
}

}  // namespace skelgraph::monitor

SKELGRAPH_REGISTER_COMPONENT(monitor, skelgraph::monitor::Monitor)
