#include "skelgraph/recording/recorder.hpp"

#include <algorithm>
#include <sstream>

#include <spdlog/spdlog.h>

#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/message_table.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/scene/scene_export.hpp"

namespace skelgraph::recording {

runtime::ComponentInfo Recorder::describe() {
  runtime::ComponentInfo info{"recorder",
                              "Records skelgraph topics to MCAP per sync session (START/STOP), answers ticks on "
                              "skelgraph/sync_ack",
                              {}};
  info.params.add_string("directory", "recordings", "where session files go (created)")
      .add_string_list("topics", {}, "topics to record (default: every skelgraph topic; depth only with include_depth)")
      .add_bool("include_depth", false, "also record skelgraph/depth (large)")
      .add_string("compression", "zstd", "chunk compression", {"none", "lz4", "zstd"})
      .add_int("flush_ms", 1000, "flush to disk at least this often: a killed recorder loses at most this much", 50, 60000)
      .add_string("host", "", "host name in file names and acks (default: the DDS host name)")
      .add_int("stop_linger_ms", 300,
               "keep recording this long after STOP, so samples in flight (the acks of the last tick) are in the file",
               0, 10000)
      .add_bool("scene", false,
                "also write the cell as a 3-D scene for Foxglove/Lichtblick into each file (skelgraph/scene/update, "
                "skelgraph/scene/transforms), as `bag export --scene` does afterwards")
      .add_bool("now", false, "record from start to shutdown without waiting for the sync topic")
      .add_string("label", "manual", "session label when recording with 'now'");
  return info;
}

Recorder::Recorder(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      record_now_(params.get<bool>("now")),
      now_label_(params.get<std::string>("label")),
      ack_pub_(ctx, runtime::topics::kSyncAck) {
  linger_ = std::chrono::milliseconds(params.get<std::int64_t>("stop_linger_ms"));
  options_.directory = params.get<std::string>("directory");
  options_.host = params.get<std::string>("host").empty() ? ctx.config().host : params.get<std::string>("host");
  options_.compression = *mcap::compression_from_name(params.get<std::string>("compression"));
  options_.flush_period_ns = params.get<std::int64_t>("flush_ms") * 1'000'000;
  if (params.get<bool>("scene")) options_.make_tap = [] { return std::make_unique<scene::SceneTap>(); };
  topics_ = params.get<std::vector<std::string>>("topics");
  const bool depth = params.get<bool>("include_depth");
  if (topics_.empty()) {
    for (const auto& t : runtime::known_topics()) {
      if (t.name != runtime::topics::kDepth.name || depth) topics_.push_back(t.name);
    }
  } else if (depth && std::find(topics_.begin(), topics_.end(), runtime::topics::kDepth.name) == topics_.end()) {
    topics_.push_back(runtime::topics::kDepth.name);
  }
  for (const auto& name : topics_) {
    const auto* t = runtime::find_topic(name);
    if (t == nullptr) throw std::invalid_argument("recorder: '" + name + "' is not a skelgraph topic");
    // A deeper history for bursts; what its writers keep all of (sync ticks, acks,
    // gesture events) the recorder keeps all of too: a recorder starved of CPU
    // for seconds holds the writers' samples instead of losing them (a loaded
    // LAN run lost a fifth of the acks from a 256-deep history).
    const auto plan = runtime::reader_plan(*t, 256, 0);
    const bool keyed = plan.keyed;
    const runtime::TopicInfo info = *t;
    subs_.push_back(std::make_unique<runtime::RawSubscription>(
        ctx, t->name, t->type_name, keyed, plan.qos,
        [this, info, keyed](const msg::RawSample& s, const runtime::SampleMeta& meta) { on_sample(info, keyed, s, meta); }));
  }
}

void Recorder::on_start() {
  if (record_now_) open(now_label_, static_cast<std::uint32_t>(ctx_.clock().now_ns() / 1'000'000'000));
  flush_timer_ = ctx_.executor().every(std::chrono::milliseconds(100), [this] {
    if (!session_) return;
    try {
      session_->maybe_flush(ctx_.clock().now_ns());
    } catch (const std::exception& e) {
      fail(e.what());
    }
  });
}

void Recorder::on_shutdown() { close(); }

// A write failed (disk full, device gone): stop this session and say why on the
// status topic. What was flushed before stays readable (`bag recover`).
void Recorder::fail(const std::string& what) {
  last_error_ = what;
  const std::string path = session_ ? session_->path() : std::string();
  session_.reset();
  const std::string salvage = path.empty() ? "" : "; salvage with: skelgraph bag recover " + path;
  ctx_.set_health(runtime::HealthState::Error, "recording stopped: " + what + salvage);
  spdlog::error("{}: recording stopped: {}", ctx_.name(), what);
}

void Recorder::open(const std::string& label, std::uint32_t session_id) {
  close();
  session_id_ = session_id;
  try {
    session_ = std::make_unique<SessionRecorder>(options_, label, session_id, ctx_.clock().now_ns());
  } catch (const std::exception& e) {
    last_error_ = e.what();
    ctx_.set_health(runtime::HealthState::Error, "cannot record session " + std::to_string(session_id) + ": " + last_error_);
    spdlog::error("{}: cannot record session {}: {}", ctx_.name(), session_id, last_error_);
    return;
  }
  ctx_.set_health(runtime::HealthState::Ok, "recording " + session_->path());
  spdlog::info("{}: recording session {} '{}' to {}", ctx_.name(), session_id, label, session_->path());
  try {
    for (const auto& l : latched_) {
      session_->record(l.topic, l.type_name, l.keyed,
                       std::string_view(reinterpret_cast<const char*>(l.cdr.data()), l.cdr.size()), l.log_ns,
                       l.publish_ns);
    }
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void Recorder::stop_session(std::chrono::milliseconds wait) {
  if (!session_) return;
  if (linger_timer_active_) {
    if (wait >= linger_wait_) return;
    linger_timer_.cancel();  // a sooner close: the STOP on the sync topic after the one on the session topic
  }
  if (wait.count() == 0) return close();
  linger_timer_active_ = true;
  linger_wait_ = wait;
  linger_timer_ = ctx_.executor().every(wait, [this] { close(); });
}

void Recorder::close() {
  linger_timer_.cancel();
  linger_timer_active_ = false;
  if (!session_) return;
  try {
    session_->finish(ctx_.clock().now_ns());
    finished_.push_back({{"file", session_->path()}, {"messages", session_->messages()}, {"counts", session_->counts()}});
    ctx_.set_health(runtime::HealthState::Ok, "wrote " + session_->path());
  } catch (const std::exception& e) {
    last_error_ = e.what();
    ctx_.set_health(runtime::HealthState::Error, "cannot finish " + session_->path() + ": " + last_error_ +
                                                      "; salvage with: skelgraph bag recover " + session_->path());
  }
  session_.reset();
}

void Recorder::on_sample(const runtime::TopicInfo& topic, bool keyed, const msg::RawSample& s,
                         const runtime::SampleMeta& m) {
  const std::string_view cdr(reinterpret_cast<const char*>(s.payload.data()), s.payload.size());
  if (topic.qos.durability == runtime::Durability::TransientLocal) {
    // As much as the topic itself keeps for late joiners (its history depth) goes into every new file.
    latched_.push_back({topic.name, topic.type_name, keyed, s.payload, m.receive_ns, m.source_stamp_ns});
    const auto keep = static_cast<std::ptrdiff_t>(std::max(1, topic.qos.depth));
    const auto same = std::count_if(latched_.begin(), latched_.end(), [&](const Latched& l) { return l.topic == topic.name; });
    if (same > keep) {
      latched_.erase(std::find_if(latched_.begin(), latched_.end(), [&](const Latched& l) { return l.topic == topic.name; }));
    }
  }
  // Session state comes on the sync topic and, for a recorder that joins late
  // (or misses the START), on the transient-local session topic.
  std::optional<msg::SyncCommand> sync;
  const bool session_topic = topic.name == runtime::topics::kSyncSession.name;
  if (topic.name == runtime::topics::kSync.name || session_topic) {
    try {
      sync = msg::from_cdr<msg::SyncCommand>(s.payload.data(), s.payload.size());
    } catch (const std::exception& e) {
      spdlog::warn("{}: undecodable sync command: {}", ctx_.name(), e.what());
    }
  }
  if (sync && sync->kind() == msg::SYNC_START && !record_now_ && session_id_ != sync->session_id()) {
    open(sync->label().to_string(), sync->session_id());
  }
  if (session_) {
    try {
      session_->record(topic.name, topic.type_name, keyed, cdr, m.receive_ns, m.source_stamp_ns);
    } catch (const std::exception& e) {
      fail(e.what());
    }
  }
  if (!sync || session_topic) {
    if (sync && session_topic && sync->kind() == msg::SYNC_STOP && !record_now_ && session_id_ == sync->session_id()) {
      // The session topic can overtake the sync topic, whose last ticks may
      // still be under repair on a lossy link: wait for the STOP there (it
      // follows every tick), or close after a grace period if it never comes.
      stop_session(std::max(linger_, kSessionStopGrace));
    }
    return;
  }
  if (sync->kind() == msg::SYNC_TICK) {
    msg::SyncAck ack;
    ack.component_name(ctx_.name().substr(0, 64));
    ack.host(options_.host.substr(0, 64));
    ack.session_id(sync->session_id());
    ack.tick(sync->tick());
    ack.master_stamp_ns(sync->master_stamp_ns());
    ack.receive_stamp_ns(m.receive_ns);
    ack.send_stamp_ns(ctx_.clock().now_ns());
    ack_pub_.publish(ack);
    ++ticks_acked_;
  } else if (sync->kind() == msg::SYNC_STOP && !record_now_) {
    stop_session(linger_);
  }
}

std::string Recorder::summary() const {
  std::ostringstream os;
  os << finished_.size() << " file(s) written";
  if (session_) os << ", recording " << session_->path() << " (" << session_->messages() << " messages)";
  os << ", " << ticks_acked_ << " ticks acked";
  if (!last_error_.empty()) os << "; error: " << last_error_;
  return os.str();
}

nlohmann::json Recorder::details() const {
  return {{"files", finished_},
          {"recording", session_ ? nlohmann::json(session_->path()) : nlohmann::json()},
          {"ticks_acked", ticks_acked_},
          {"topics", topics_},
          {"host", options_.host},
          {"error", last_error_}};
}

}  // namespace skelgraph::recording

SKELGRAPH_REGISTER_COMPONENT(recorder, skelgraph::recording::Recorder)
