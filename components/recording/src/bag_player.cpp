#include "skelgraph/recording/bag_player.hpp"

#include <algorithm>
#include <climits>
#include <sstream>

#include "skelgraph/msg/schema.hpp"
#include "skelgraph/runtime/ordered_queue.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::recording {

runtime::ComponentInfo BagPlayer::describe() {
  runtime::ComponentInfo info{"bag_player", "Republishes an MCAP recording with its original timing, topics and keys", {}};
  info.params.add_string("file", "", "the recording (MCAP)")
      .add_double("rate", 1.0, "speed: 1 = as recorded, 2 = twice as fast", 0.01, 1000.0)
      .add_bool("loop", false, "start again at the end")
      .add_bool("paused", false, "start paused (resume, step or seek on skelgraph/play/control)")
      .add_bool("hold_at_end", false, "at the end, wait for a seek instead of finishing")
      .add_double("wait_s", 2.0, "before playing, wait up to this long for every topic to have a reader", 0.0, 60.0)
      .add_double("reorder_s", 2.0, "messages this much out of log-time order in the file are played in order", 0.0, 60.0)
      .add_string_list("topics", {}, "only these topics (default: all but skelgraph/status)")
      .add_double("gone_after_s", 1.0,
                  "a keyed stream (a person, a sensor) absent from the recording this long (its own time) has left: "
                  "its instance is disposed; also at the end and on a seek",
                  0.05, 3600.0);
  return info;
}

namespace {
mcap::Reader open_recording(const std::string& file) {
  if (file.empty()) throw std::invalid_argument("parameter 'file' names no recording");
  return mcap::Reader(file);  // McapError names what is wrong and where
}
}  // namespace

BagPlayer::BagPlayer(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      file_(params.get<std::string>("file")),
      rate_(params.get<double>("rate")),
      loop_(params.get<bool>("loop")),
      hold_at_end_(params.get<bool>("hold_at_end")),
      wait_ns_(static_cast<std::int64_t>(params.get<double>("wait_s") * 1e9)),
      reorder_ns_(static_cast<std::uint64_t>(params.get<double>("reorder_s") * 1e9)),
      gone_after_ns_(static_cast<std::int64_t>(params.get<double>("gone_after_s") * 1e9)),
      reader_(open_recording(file_)) {
  const auto wanted = params.get<std::vector<std::string>>("topics");
  const auto summary = reader_.summary();  // from the summary section when there is one; else a scan
  bool any = false;
  for (const auto& [id, ch] : summary.channels) {
    const bool selected = wanted.empty() ? ch.topic != runtime::topics::kStatus.name
                                         : std::find(wanted.begin(), wanted.end(), ch.topic) != wanted.end();
    const auto count = summary.channel_message_counts.count(id) ? summary.channel_message_counts.at(id) : 0;
    if (!selected || count == 0) continue;
    const auto type = ch.metadata.count("dds_type") ? ch.metadata.at("dds_type") : std::string();
    if (type.empty()) throw std::invalid_argument(file_ + ": channel " + ch.topic + " has no DDS type name");
    const auto schema = summary.schemas.find(ch.schema_id);
    if (msg::may_be_older_schema(type, schema == summary.schemas.end() ? std::string() : schema->second.data))
      older_schema_[id] = type;
    const bool keyed = ch.metadata.count("keyed") && ch.metadata.at("keyed") == "true";
    const auto* known = runtime::find_topic(ch.topic);
    runtime::QosPreset qos = known ? known->qos : runtime::QosPreset{};
    if (qos.depth == 0) qos.depth = 256;
    // Several channels may carry one topic (recordings merged from hosts): one writer per topic.
    const auto same = std::find(publisher_topics_.begin(), publisher_topics_.end(), ch.topic);
    if (same != publisher_topics_.end()) {
      publisher_of_channel_[id] = static_cast<std::size_t>(same - publisher_topics_.begin());
    } else {
      publisher_of_channel_[id] = publishers_.size();
      publishers_.push_back(std::make_unique<runtime::RawPublisher>(ctx, ch.topic, type, keyed, qos));
      publisher_topics_.push_back(ch.topic);
      publisher_is_state_.push_back(qos.durability == runtime::Durability::TransientLocal);
    }
    per_pass_ += count;
    any = true;
  }
  if (!any) throw std::invalid_argument(file_ + ": no messages to play");
  first_log_time_ = summary.message_start_time;
  last_log_time_ = std::max(summary.message_end_time, first_log_time_);
  position_log_ = first_log_time_;
  player_ = std::make_unique<runtime::PlayerLink>(ctx, runtime::PlayGate(rate_, params.get<bool>("paused")),
                                                  [this] { return progress(); }, /*can_seek=*/true);
}

runtime::PlayerLink::Progress BagPlayer::progress() const {
  runtime::PlayerLink::Progress p;
  p.frames = published_;
  p.frame_count = static_cast<std::int64_t>(per_pass_);
  p.at_end = at_end_;
  p.position_s = static_cast<double>(position_log_.load() - first_log_time_) / 1e9;
  p.duration_s = static_cast<double>(last_log_time_ - first_log_time_) / 1e9;
  return p;
}

BagPlayer::~BagPlayer() { on_shutdown(); }

void BagPlayer::on_start() {
  player_->publish_state();
  thread_ = std::thread([this] { run(); });
}

void BagPlayer::on_shutdown() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void BagPlayer::run() {
  try {
    wait_for_readers();
    std::uint64_t from = first_log_time_;
    for (;;) {
      try {
        at_end_ = false;
        play_once(from);
        dispose_idle(INT64_MAX);  // the end of the recording: everyone has left
      } catch (const SeekTo& s) {
        dispose_idle(INT64_MAX);  // elsewhere in the recording, other people may be there
        from = s.log_time;
        position_log_ = from;
        at_end_ = false;
        player_->sought();
        continue;
      }
      ++loops_;
      from = first_log_time_;
      if (loop_) continue;
      at_end_ = true;
      player_->at_end();
      if (!hold_at_end_) break;
      // Held at the end: a seek plays on from there.
      try {
        for (;;) {
          check_stop_and_seek();
          player_->wait_for_request(std::chrono::milliseconds(50));
        }
      } catch (const SeekTo& s) {
        from = s.log_time;
        position_log_ = from;
        at_end_ = false;
        player_->sought();
      }
    }
    // Reliable readers acknowledge the last samples before the graph may stop (bounded: 2 s in all).
    const auto acks_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    for (auto& p : publishers_) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(acks_deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0 || !p->wait_for_acks(left)) break;
    }
    ctx_.set_health(failed_ ? runtime::HealthState::Degraded : runtime::HealthState::Ok,
                    failed_ ? std::to_string(failed_.load()) + " message(s) could not be republished" : "finished");
    done_ = true;
  } catch (const Stopped&) {
  } catch (const std::exception& e) {
    ctx_.set_health(runtime::HealthState::Error, std::string("playback stopped: ") + e.what());
    done_ = true;
  }
}

// Best-effort samples written before discovery matched a reader are lost: wait for readers first.
// A writer matches a reader before that reader has matched the writer; give the other side 0.5 s more.
void BagPlayer::wait_for_readers() {
  const auto t0 = ctx_.clock().monotonic_ns();
  std::int64_t matched_at = 0;
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const auto now = ctx_.clock().monotonic_ns();
    const bool all = std::all_of(publishers_.begin(), publishers_.end(), [](const auto& p) { return p->matched() > 0; });
    if (all && matched_at == 0) matched_at = now;
    if ((matched_at != 0 && now - matched_at >= 500'000'000) || now - t0 >= wait_ns_) return;
    cv_.wait_for(lock, std::chrono::milliseconds(10));
  }
  throw Stopped{};
}

void BagPlayer::check_stop_and_seek() {
  {
    std::lock_guard lock(mutex_);
    if (stop_) throw Stopped{};
  }
  const auto seek = player_->with_gate([](runtime::PlayGate& g) { return g.take_seek(); });
  if (seek) {
    const auto offset = static_cast<std::uint64_t>(*seek * 1e9);
    pace_mono_ = 0;  // pace afresh from the first message played
    throw SeekTo{first_log_time_ + std::min(offset, last_log_time_ - first_log_time_)};
  }
}

bool BagPlayer::wait_until_due(std::uint64_t log_time) {
  for (;;) {
    check_stop_and_seek();
    const auto [deliver, repace, stepping, speed] = player_->turn();
    if (!deliver) {  // paused
      player_->wait_for_request(std::chrono::milliseconds(50));
      continue;
    }
    const auto now = ctx_.clock().monotonic_ns();
    if (repace || pace_mono_ == 0) {
      pace_mono_ = now;
      pace_log_ = log_time;
    }
    if (stepping || speed <= 0.0) return stepping;  // steps, and speed 0, do not wait
    const auto due = pace_mono_ + static_cast<std::int64_t>(static_cast<double>(log_time - pace_log_) / speed);
    if (now >= due) return false;
    player_->wait_for_request(std::chrono::nanoseconds(std::min<std::int64_t>(due - now, 50'000'000)));
  }
}

void BagPlayer::play_once(std::uint64_t from) {
  struct Pending {
    std::size_t publisher;
    msg::RawSample sample;
  };
  // Messages up to reorder_s out of log-time order in the file are played in order.
  runtime::OrderedQueue<Pending> pending;
  pending.add_stream(0, static_cast<std::int64_t>(reorder_ns_));
  std::uint64_t last_played = 0;
  const auto play = [&](std::int64_t log_time, Pending&& p) {
    const auto lt = static_cast<std::uint64_t>(log_time);
    if (lt < last_played) ++reordered_late_;  // further out of order than reorder_s
    last_played = std::max(last_played, lt);
    const auto t = std::max(lt, first_log_time_);
    if (t < from) {  // before a seek's position: only the latest state matters
      if (publisher_is_state_[p.publisher]) publishers_[p.publisher]->publish(p.sample);
      return;
    }
    const bool stepped = wait_until_due(t);
    if (publishers_[p.publisher]->publish(p.sample, static_cast<std::int64_t>(t))) ++published_;
    else ++failed_;
    if (t - last_idle_check_ >= 100'000'000) {
      last_idle_check_ = t;
      dispose_idle(static_cast<std::int64_t>(t) - gone_after_ns_);
    }
    position_log_ = t;
    player_->delivered(stepped);
    const auto now = ctx_.clock().monotonic_ns();
    if (now - last_state_ns_ >= 250'000'000) {
      last_state_ns_ = now;
      player_->publish_state();
    }
  };
  reader_.for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
    const auto it = publisher_of_channel_.find(ch.id);
    if (it == publisher_of_channel_.end()) return;
    Pending p{it->second, {}};
    const auto older = older_schema_.find(ch.id);
    auto upgraded = older == older_schema_.end() ? std::nullopt
                                                 : msg::upgrade_cdr(older->second, m.data.data(), m.data.size());
    if (upgraded) p.sample.payload = std::move(*upgraded);
    else p.sample.payload.assign(m.data.begin(), m.data.end());
    pending.push(0, static_cast<std::int64_t>(m.log_time), std::move(p));
    pending.drain(play);
  });
  pending.flush(play);
}

// Keyed streams of live topics not seen since `before_log_ns` are disposed
// (state topics, such as sensor poses, stay as a late joiner would find them).
void BagPlayer::dispose_idle(std::int64_t before_log_ns) {
  for (std::size_t i = 0; i < publishers_.size(); ++i) {
    if (!publisher_is_state_[i]) publishers_[i]->dispose_idle(before_log_ns);
  }
  if (before_log_ns == INT64_MAX) last_idle_check_ = 0;
}

std::string BagPlayer::summary() const {
  std::ostringstream os;
  os << "published " << published_ << " of " << per_pass_ << " messages on " << publishers_.size() << " topic(s)";
  if (loops_ > 0) os << ", " << loops_ << " pass(es)";
  if (failed_ > 0) os << ", " << failed_ << " failed";
  if (reordered_late_ > 0) os << ", " << reordered_late_ << " played late (out of order in the file)";
  return os.str();
}

nlohmann::json BagPlayer::details() const {
  return {{"file", file_},           {"messages", per_pass_},        {"published", published_.load()},
          {"position_s", progress().position_s}, {"duration_s", progress().duration_s},
          {"failed", failed_.load()}, {"passes", loops_.load()},      {"played_late", reordered_late_.load()},
          {"topics", publisher_topics_}};
}

}  // namespace skelgraph::recording

SKELGRAPH_REGISTER_COMPONENT(bag_player, skelgraph::recording::BagPlayer)
