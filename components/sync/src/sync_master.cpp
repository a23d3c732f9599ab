#include "skelgraph/sync/sync_master.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

#include <spdlog/spdlog.h>

namespace skelgraph::sync {

namespace {
SyncMasterCore::Config config_from(const runtime::Params& p) {
  SyncMasterCore::Config c;
  c.tick_period_ns = static_cast<std::int64_t>(std::llround(p.get<double>("tick_period_ms") * 1e6));
  c.session_duration_ns = static_cast<std::int64_t>(std::llround(p.get<double>("session_duration_s") * 1e9));
  return c;
}

msg::SyncKind to_msg(SyncEvent::Kind k) {
  switch (k) {
    case SyncEvent::Kind::Start: return msg::SYNC_START;
    case SyncEvent::Kind::Stop: return msg::SYNC_STOP;
    case SyncEvent::Kind::Tick: return msg::SYNC_TICK;
  }
  return msg::SYNC_TICK;
}
}  // namespace

runtime::ComponentInfo SyncMaster::describe() {
  runtime::ComponentInfo info{"sync_master",
                              "Publishes START/TICK/STOP on skelgraph/sync so recorders on every host act in step",
                              {}};
  info.params.add_double("tick_period_ms", 33.0, "time between TICKs (the thesis used 33 ms)", 1.0, 10000.0)
      .add_bool("autostart", true, "start a session as soon as the component starts")
      .add_string("label", "session", "label of the automatically started session")
      .add_double("session_duration_s", 0.0, "stop the session after this long (0: run until stopped)", 0.0);
  return info;
}

SyncMaster::SyncMaster(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      core_(config_from(params)),
      autostart_(params.get<bool>("autostart")),
      label_(params.get<std::string>("label")),
      sync_pub_(ctx, runtime::topics::kSync),
      session_pub_(ctx, runtime::topics::kSyncSession),
      control_sub_(ctx, runtime::topics::kSyncControl,
                   [this](const msg::SyncControl& c, const runtime::SampleMeta&) { on_control(c); }),
      ack_sub_(ctx, runtime::topics::kSyncAck, [this](const msg::SyncAck& a, const runtime::SampleMeta& m) { on_ack(a, m); }),
      clock_pub_(ctx, runtime::topics::kSyncClock) {}

void SyncMaster::on_ack(const msg::SyncAck& a, const runtime::SampleMeta& m) {
  const auto host = a.host().size() > 0 ? a.host().to_string() : a.component_name().to_string();
  auto& clock = clocks_[host];
  // t4: when the ack reached us, on our clock (taken on the executor: includes its queueing, which the
  // round-trip filter tolerates).
  if (!clock.estimator.add({a.master_stamp_ns(), a.receive_stamp_ns(), a.send_stamp_ns(), m.receive_ns})) return;
  if (m.receive_ns - clock.published_ns < 1'000'000'000) return;
  clock.last = clock.estimator.estimate();
  if (!clock.last) return;
  msg::ClockOffset c;
  c.host(host.substr(0, 64));
  c.session_id(a.session_id());
  c.offset_ns(clock.last->offset_ns);
  c.drift_ppm(clock.last->drift_ppm);
  c.rtt_ns(clock.last->rtt_ns);
  c.samples(static_cast<std::uint32_t>(clock.last->samples));
  c.stamp_ns(m.receive_ns);
  clock_pub_.publish(c);
  clock.published_ns = m.receive_ns;
}

std::int64_t SyncMaster::mono_ns() const { return ctx_.clock().monotonic_ns(); }

void SyncMaster::start_session(const std::string& label, const std::string& request_id) {
  // The timer starts with the session, so each firing finds exactly one tick due.
  publish(core_.start(label, mono_ns(), ctx_.clock().now_ns(), request_id));
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(core_.config().tick_period_ns), [this] {
    publish(core_.advance(mono_ns(), ctx_.clock().now_ns()));
    if (!core_.running()) timer_.cancel();  // the session's duration ran out
  });
}

void SyncMaster::on_start() {
  if (autostart_) start_session(label_, {});
}

void SyncMaster::on_shutdown() {
  timer_.cancel();
  publish(core_.stop(ctx_.clock().now_ns()));
}

void SyncMaster::on_control(const msg::SyncControl& c) {
  // Requesters repeat a request until answered: each request id is handled once.
  const auto id = c.request_id().to_string();
  if (!id.empty() && id == last_request_id_) return;
  last_request_id_ = id;
  if (c.kind() == msg::SYNC_START) {
    const auto label = c.label().size() == 0 ? label_ : c.label().to_string();
    spdlog::info("{}: START '{}' requested by {}", ctx_.name(), label, c.requester().to_string());
    start_session(label, c.request_id().to_string());
  } else if (c.kind() == msg::SYNC_STOP) {
    spdlog::info("{}: STOP requested by {}", ctx_.name(), c.requester().to_string());
    timer_.cancel();
    publish(core_.stop(ctx_.clock().now_ns(), c.request_id().to_string()));
  }
}

void SyncMaster::publish(const std::vector<SyncEvent>& events) {
  for (const auto& e : events) {
    msg::SyncCommand m;
    m.kind(to_msg(e.kind));
    m.session_id(e.session_id);
    m.label(e.label.substr(0, 128));
    m.tick(e.tick);
    m.master_stamp_ns(e.stamp_ns);
    m.request_id(e.request_id.substr(0, 64));
    sync_pub_.publish(m);
    if (e.kind != SyncEvent::Kind::Tick) session_pub_.publish(m);
  }
}

nlohmann::json SyncMaster::details() const {
  nlohmann::json clocks = nlohmann::json::object();
  for (const auto& [host, c] : clocks_) {
    if (!c.last) continue;
    clocks[host] = {{"offset_ns", c.last->offset_ns}, {"drift_ppm", c.last->drift_ppm},
                    {"rtt_ns", c.last->rtt_ns},       {"samples", c.last->samples}};
  }
  return {{"sessions_started", core_.sessions_started()}, {"session_id", core_.session_id()},
          {"label", core_.label()},                       {"running", core_.running()},
          {"ticks_sent", core_.ticks_sent()},             {"ticks_skipped", core_.ticks_skipped()},
          {"clocks", clocks}};
}

std::string SyncMaster::summary() const {
  std::ostringstream os;
  os << core_.sessions_started() << " session(s); last " << core_.session_id() << " '" << core_.label() << "' "
     << (core_.running() ? "running" : "stopped") << " after " << core_.ticks_sent() << " ticks";
  if (core_.ticks_skipped() > 0) os << " (" << core_.ticks_skipped() << " skipped after stalls)";
  return os.str();
}

}  // namespace skelgraph::sync

SKELGRAPH_REGISTER_COMPONENT(sync_master, skelgraph::sync::SyncMaster)
