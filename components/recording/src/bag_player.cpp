#include "skelgraph/recording/bag_player.hpp"

#include <algorithm>
#include <map>
#include <sstream>

#include "skelgraph/msg/message_table.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::recording {

runtime::ComponentInfo BagPlayer::describe() {
  runtime::ComponentInfo info{"bag_player", "Republishes an MCAP recording with its original timing, topics and keys", {}};
  info.params.add_string("file", "", "the recording (MCAP)")
      .add_double("rate", 1.0, "speed: 1 = as recorded, 2 = twice as fast", 0.01, 1000.0)
      .add_bool("loop", false, "start again at the end")
      .add_double("wait_s", 2.0, "before playing, wait up to this long for every topic to have a reader", 0.0, 60.0)
      .add_string_list("topics", {}, "only these topics (default: all but skelgraph/status)");
  return info;
}

BagPlayer::BagPlayer(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      file_(params.get<std::string>("file")),
      rate_(params.get<double>("rate")),
      loop_(params.get<bool>("loop")),
      wait_ns_(static_cast<std::int64_t>(params.get<double>("wait_s") * 1e9)) {
  if (file_.empty()) throw std::invalid_argument("parameter 'file' names no recording");
  const auto wanted = params.get<std::vector<std::string>>("topics");
  const mcap::Reader reader(file_);  // McapError names what is wrong and where
  std::map<std::uint16_t, std::size_t> by_channel;
  reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
    auto it = by_channel.find(ch.id);
    if (it == by_channel.end()) {
      const bool selected = wanted.empty() ? ch.topic != runtime::topics::kStatus.name
                                           : std::find(wanted.begin(), wanted.end(), ch.topic) != wanted.end();
      std::size_t index = SIZE_MAX;
      if (selected) {
        const auto type = ch.metadata.count("dds_type") ? ch.metadata.at("dds_type") : std::string();
        if (type.empty()) throw std::invalid_argument(file_ + ": channel " + ch.topic + " has no DDS type name");
        const bool keyed = ch.metadata.count("keyed") && ch.metadata.at("keyed") == "true";
        const auto* known = runtime::find_topic(ch.topic);
        runtime::QosPreset qos = known ? known->qos : runtime::QosPreset{};
        if (qos.depth == 0) qos.depth = 256;
        index = publishers_.size();
        publishers_.push_back(std::make_unique<runtime::RawPublisher>(ctx, ch.topic, type, keyed, qos));
        publisher_topics_.push_back(ch.topic);
      }
      it = by_channel.emplace(ch.id, index).first;
    }
    if (it->second == SIZE_MAX) return;
    Item item{it->second, m.log_time, {}};
    item.sample.payload.assign(m.data.begin(), m.data.end());
    items_.push_back(std::move(item));
  });
  std::stable_sort(items_.begin(), items_.end(), [](const Item& a, const Item& b) { return a.log_time < b.log_time; });
  if (items_.empty()) throw std::invalid_argument(file_ + ": no messages to play");
}

void BagPlayer::on_start() {
  start_mono_ns_ = runtime::Context::monotonic_ns();
  timer_ = ctx_.executor().every(std::chrono::milliseconds(2), [this] { tick(); }, true);
}

void BagPlayer::tick() {
  if (!playing_) {
    // Best-effort samples written before discovery matched a reader are lost: wait for readers first.
    // A writer matches a reader before that reader has matched the writer; give the other side 0.5 s more.
    const auto now = runtime::Context::monotonic_ns();
    const bool all_matched = std::all_of(publishers_.begin(), publishers_.end(), [](const auto& p) { return p->matched() > 0; });
    if (all_matched && matched_at_ == 0) matched_at_ = now;
    const bool settled = matched_at_ != 0 && now - matched_at_ >= 500'000'000;
    if (!settled && now - start_mono_ns_ < wait_ns_) return;
    playing_ = true;
    start_mono_ns_ = runtime::Context::monotonic_ns();
  }
  const auto first = items_.front().log_time;
  const double elapsed = static_cast<double>(runtime::Context::monotonic_ns() - start_mono_ns_) * rate_;
  while (next_ < items_.size() && static_cast<double>(items_[next_].log_time - first) <= elapsed) {
    const auto& it = items_[next_++];
    if (publishers_[it.publisher]->publish(it.sample)) ++published_;
    else ++failed_;
  }
  if (next_ < items_.size()) return;
  ++loops_;
  if (loop_) {
    next_ = 0;
    start_mono_ns_ = runtime::Context::monotonic_ns();
    return;
  }
  timer_.cancel();
  ctx_.set_health(failed_ ? runtime::HealthState::Degraded : runtime::HealthState::Ok,
                  failed_ ? std::to_string(failed_) + " message(s) could not be republished" : "finished");
}

std::string BagPlayer::summary() const {
  std::ostringstream os;
  os << "published " << published_ << " of " << items_.size() << " messages on " << publishers_.size() << " topic(s)";
  if (loops_ > 0) os << ", " << loops_ << " pass(es)";
  if (failed_ > 0) os << ", " << failed_ << " failed";
  return os.str();
}

nlohmann::json BagPlayer::details() const {
  return {{"file", file_}, {"messages", items_.size()}, {"published", published_}, {"failed", failed_},
          {"passes", loops_}, {"topics", publisher_topics_}};
}

}  // namespace skelgraph::recording

SKELGRAPH_REGISTER_COMPONENT(bag_player, skelgraph::recording::BagPlayer)
