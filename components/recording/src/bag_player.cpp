#include "skelgraph/recording/bag_player.hpp"

#include <algorithm>
#include <queue>
#include <sstream>

#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::recording {

runtime::ComponentInfo BagPlayer::describe() {
  runtime::ComponentInfo info{"bag_player", "Republishes an MCAP recording with its original timing, topics and keys", {}};
  info.params.add_string("file", "", "the recording (MCAP)")
      .add_double("rate", 1.0, "speed: 1 = as recorded, 2 = twice as fast", 0.01, 1000.0)
      .add_bool("loop", false, "start again at the end")
      .add_double("wait_s", 2.0, "before playing, wait up to this long for every topic to have a reader", 0.0, 60.0)
      .add_double("reorder_s", 2.0, "messages this much out of log-time order in the file are played in order", 0.0, 60.0)
      .add_string_list("topics", {}, "only these topics (default: all but skelgraph/status)");
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
      wait_ns_(static_cast<std::int64_t>(params.get<double>("wait_s") * 1e9)),
      reorder_ns_(static_cast<std::uint64_t>(params.get<double>("reorder_s") * 1e9)),
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
    }
    per_pass_ += count;
    any = true;
  }
  if (!any) throw std::invalid_argument(file_ + ": no messages to play");
  first_log_time_ = summary.message_start_time;
}

BagPlayer::~BagPlayer() { on_shutdown(); }

void BagPlayer::on_start() { thread_ = std::thread([this] { run(); }); }

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
    do {
      start_mono_ns_ = runtime::Context::monotonic_ns();
      play_once();
      ++loops_;
    } while (loop_);
    {  // let readers take (and reliable readers acknowledge) the last samples before the graph may stop
      std::unique_lock lock(mutex_);
      cv_.wait_for(lock, std::chrono::milliseconds(500), [this] { return stop_; });
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
  const auto t0 = runtime::Context::monotonic_ns();
  std::int64_t matched_at = 0;
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const auto now = runtime::Context::monotonic_ns();
    const bool all = std::all_of(publishers_.begin(), publishers_.end(), [](const auto& p) { return p->matched() > 0; });
    if (all && matched_at == 0) matched_at = now;
    if ((matched_at != 0 && now - matched_at >= 500'000'000) || now - t0 >= wait_ns_) return;
    cv_.wait_for(lock, std::chrono::milliseconds(10));
  }
  throw Stopped{};
}

void BagPlayer::wait_until_due(std::uint64_t log_time) {
  const auto offset = static_cast<std::int64_t>(static_cast<double>(log_time - first_log_time_) / rate_);
  const auto due = start_mono_ns_ + offset;
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const auto now = runtime::Context::monotonic_ns();
    if (now >= due) return;
    cv_.wait_for(lock, std::chrono::nanoseconds(std::min<std::int64_t>(due - now, 100'000'000)));
  }
  throw Stopped{};
}

void BagPlayer::play_once() {
  struct Pending {
    std::uint64_t log_time, order;
    std::size_t publisher;
    msg::RawSample sample;
  };
  const auto later = [](const Pending& a, const Pending& b) {
    return a.log_time != b.log_time ? a.log_time > b.log_time : a.order > b.order;
  };
  std::priority_queue<Pending, std::vector<Pending>, decltype(later)> pending(later);
  std::uint64_t order = 0, newest = 0, last_played = 0;
  const auto play = [&] {
    auto p = pending.top();  // copy: pop() below invalidates it
    pending.pop();
    if (p.log_time < last_played) ++reordered_late_;  // further out of order than reorder_s
    last_played = std::max(last_played, p.log_time);
    wait_until_due(std::max(p.log_time, first_log_time_));
    if (publishers_[p.publisher]->publish(p.sample)) ++published_;
    else ++failed_;
  };
  reader_.for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
    const auto it = publisher_of_channel_.find(ch.id);
    if (it == publisher_of_channel_.end()) return;
    Pending p{m.log_time, order++, it->second, {}};
    p.sample.payload.assign(m.data.begin(), m.data.end());
    pending.push(std::move(p));
    newest = std::max(newest, m.log_time);
    while (!pending.empty() && pending.top().log_time + reorder_ns_ <= newest) play();
  });
  while (!pending.empty()) play();
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
          {"failed", failed_.load()}, {"passes", loops_.load()},      {"played_late", reordered_late_.load()},
          {"topics", publisher_topics_}};
}

}  // namespace skelgraph::recording

SKELGRAPH_REGISTER_COMPONENT(bag_player, skelgraph::recording::BagPlayer)
