#include "skelgraph/recording/merge.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <tuple>
#include <unordered_map>

#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/schema.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/recording/tick_frames.hpp"
#include "skelgraph/runtime/ordered_queue.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::recording {

namespace {

namespace topics = runtime::topics;


struct Item {
  std::uint64_t time = 0;  // on the master's clock
  std::string topic, type;
  bool keyed = false;
  std::string data;
  std::uint64_t publish_time = 0;
  std::size_t input = 0;
};

// One input's messages, handed from its reader thread to the merge.
struct Feed {
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<Item> ready;
  std::size_t bytes = 0;  // of the messages ready
  bool done = false, abandoned = false;
  std::exception_ptr error;
};

struct Abandoned {};  // thrown inside a reader's scan when the merge has given up

// Two independent 64-bit hashes of the bytes: the same message from two hosts is one.
struct Fingerprint {
  std::uint64_t a = 0, b = 0;
  bool operator==(const Fingerprint& o) const { return a == o.a && b == o.b; }
};
struct FingerprintHash {
  std::size_t operator()(const Fingerprint& f) const { return static_cast<std::size_t>(f.a ^ (f.b * 0x9e3779b97f4a7c15ULL)); }
};
Fingerprint fingerprint(const std::string& topic, const std::string& data) {
  Fingerprint f;
  f.a = std::hash<std::string>{}(topic + '\0' + data);
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (const unsigned char c : topic) h = (h ^ c) * 1099511628211ULL;
  for (const unsigned char c : data) h = (h ^ c) * 1099511628211ULL;
  f.b = h ^ data.size();
  return f;
}

}  // namespace

MergeReport merge_recordings(const std::vector<std::string>& files, const std::string& out_path,
                             const MergeOptions& options) {
  MergeReport report;
  report.out = out_path;
  // 1. Each input once: its host, every clock estimate, the acks and sessions.
  std::map<std::string, msg::ClockOffset> clocks;  // latest per host
  AckTally acks;
  std::vector<std::unique_ptr<mcap::Reader>> readers;
  for (const auto& f : files) {
    readers.push_back(std::make_unique<mcap::Reader>(f));
    std::string host;
    readers.back()->for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
      if (ch.topic == topics::kSyncClock.name) {
        auto c = msg::from_cdr<msg::ClockOffset>(m.data.data(), m.data.size());
        auto& slot = clocks[c.host().to_string()];
        if (c.stamp_ns() >= slot.stamp_ns()) slot = c;
      } else if (ch.topic == topics::kSyncAck.name) {
        acks.ack(msg::from_cdr<msg::SyncAck>(m.data.data(), m.data.size()));
      } else if (ch.topic == topics::kSync.name) {
        acks.session(msg::from_cdr<msg::SyncCommand>(m.data.data(), m.data.size()).session_id());
      }
    });
    for (const auto& m : readers.back()->summary().metadata) {
      if (m.name == "session" && m.values.count("host")) host = m.values.at("host");
    }
    if (host.empty()) throw MergeError(f + ": no session metadata naming its host (not written by the recorder?)");
    report.inputs.push_back({f, host});
  }
  for (auto& in : report.inputs) {
    const auto it = clocks.find(in.host);
    if (it == clocks.end()) continue;
    in.offset_ns = static_cast<double>(it->second.offset_ns());
    in.drift_ppm = it->second.drift_ppm();
    in.estimated = true;
  }
  report.ticks_acked_by_host = acks.by_host();

  mcap::WriterOptions wo;
  wo.compression = options.compression;
  BagWriter bag(out_path, wo);

  // 2. The messages: a reader thread per input, interleaved in time order.
  std::vector<std::unique_ptr<Feed>> feeds;
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < files.size(); ++i) feeds.push_back(std::make_unique<Feed>());
  const auto read_input = [&](std::size_t i) {
    Feed& feed = *feeds[i];
    const auto& in = report.inputs[i];
    const double drift = in.drift_ppm * 1e-6;
    const auto c = clocks.find(in.host);
    const double at = c == clocks.end() ? 0.0 : static_cast<double>(c->second.stamp_ns());
    try {
      readers[i]->for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
        Item item;
        item.type = ch.metadata.count("dds_type") ? ch.metadata.at("dds_type") : std::string();
        // Older schemas are written in the current one (the merged file's schema is the current IDL).
        auto upgraded = msg::may_be_older_schema(item.type, schema ? schema->data : std::string())
                            ? msg::upgrade_cdr(item.type, m.data.data(), m.data.size())
                            : std::nullopt;
        item.data = upgraded ? std::string(upgraded->begin(), upgraded->end()) : std::string(m.data);
        // Host clock -> master clock: subtract the offset the host had at that moment.
        const double t = static_cast<double>(m.log_time);
        item.time = static_cast<std::uint64_t>(std::max(0.0, t - (in.offset_ns + drift * (t - at))));
        item.topic = ch.topic;
        item.keyed = ch.metadata.count("keyed") && ch.metadata.at("keyed") == "true";
        item.publish_time = m.publish_time;
        item.input = i;
        std::unique_lock<std::mutex> lock(feed.mutex);
        feed.changed.wait(lock, [&] { return feed.bytes < options.queue_bytes || feed.abandoned; });
        if (feed.abandoned) throw Abandoned{};
        feed.bytes += item.data.size() + item.topic.size() + sizeof(Item);
        feed.ready.push_back(std::move(item));
        feed.changed.notify_all();
      });
    } catch (const Abandoned&) {
    } catch (...) {
      std::lock_guard<std::mutex> lock(feed.mutex);
      feed.error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(feed.mutex);
    feed.done = true;
    feed.changed.notify_all();
  };
  for (std::size_t i = 0; i < files.size(); ++i) threads.emplace_back(read_input, i);
  const auto stop_readers = [&] {
    for (auto& f : feeds) {
      std::lock_guard<std::mutex> lock(f->mutex);
      f->abandoned = true;
      f->changed.notify_all();
    }
    for (auto& t : threads)
      if (t.joinable()) t.join();
  };

  TickAssociator assoc(static_cast<std::int64_t>(options.max_age_ms * 1e6));
  // The duplicate window: fingerprints of what was written, with the input that had it first.
  std::unordered_map<Fingerprint, std::pair<std::size_t, std::uint64_t>, FingerprintHash> recent;
  std::deque<std::pair<std::uint64_t, Fingerprint>> recent_order;
  const auto window_ns = static_cast<std::uint64_t>(options.duplicate_window_s * 1e9);
  std::uint64_t last_written = 0;
  const auto write = [&](std::int64_t, Item&& it) {
    while (!recent_order.empty() && recent_order.front().first + window_ns < it.time) {
      const auto old = recent.find(recent_order.front().second);
      if (old != recent.end() && old->second.second == recent_order.front().first) recent.erase(old);
      recent_order.pop_front();
    }
    const auto fp = fingerprint(it.topic, it.data);
    const auto [where, fresh] = recent.try_emplace(fp, it.input, it.time);
    if (!fresh && where->second.first != it.input) {  // another host recorded the same sample
      ++report.duplicates_dropped;
      return;
    }
    where->second.second = it.time;
    recent_order.emplace_back(it.time, fp);
    if (it.time < last_written) ++report.out_of_order;
    last_written = std::max(last_written, it.time);
    bag.write_cdr(it.topic, it.type, it.keyed, it.data, it.time, it.publish_time);
    ++report.messages;
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(it.data.data());
    msg::FrameRef f;
    if (it.type == msg::MessageTraits<msg::Skeleton>::name) {
      const auto k = msg::from_cdr<msg::Skeleton>(bytes, it.data.size());
      f.sensor_id(k.sensor_id());
      f.person_id(k.person_id());
      f.frame_number(k.frame_number());
      f.stamp_ns(k.stamp_ns());
    } else if (it.type == msg::MessageTraits<msg::DepthFrame>::name) {
      const auto d = msg::from_cdr<msg::DepthFrame>(bytes, it.data.size());
      f.sensor_id(d.sensor_id());
      f.frame_number(d.frame_number());
      f.stamp_ns(d.stamp_ns());
    } else if (it.topic == topics::kSync.name) {
      const auto c = msg::from_cdr<msg::SyncCommand>(bytes, it.data.size());
      if (c.kind() != msg::SYNC_TICK) return;
      const auto tf = assoc.tick(c.session_id(), c.tick(), c.master_stamp_ns(), static_cast<std::int64_t>(it.time));
      bag.write(kTickFramesTopic, tf, it.time, it.time);
      ++report.messages;
      ++report.tick_records;
      report.frames_at_ticks += tf.frames().size();
      return;
    } else {
      return;
    }
    f.topic(it.topic.substr(0, 128));
    f.host(report.inputs[it.input].host.substr(0, 64));
    f.log_time_ns(static_cast<std::int64_t>(it.time));
    assoc.frame(f);
  };

  try {
    runtime::OrderedQueue<Item> queue;
    for (std::size_t i = 0; i < files.size(); ++i) queue.add_stream(i, static_cast<std::int64_t>(options.reorder_s * 1e9));
    // Take from the input that holds the queue back until every input is done.
    while (const auto who = queue.blocker()) {
      Feed& feed = *feeds[*who];
      std::deque<Item> batch;
      bool finished = false;
      {
        std::unique_lock<std::mutex> lock(feed.mutex);
        feed.changed.wait(lock, [&] { return !feed.ready.empty() || feed.done; });
        batch.swap(feed.ready);
        feed.bytes = 0;
        if (batch.empty() && feed.done) {
          if (feed.error) std::rethrow_exception(feed.error);
          finished = true;
        }
        feed.changed.notify_all();
      }
      if (finished) {
        queue.finish(*who);
      } else {
        for (auto& it : batch) queue.push(*who, static_cast<std::int64_t>(it.time), std::move(it));
      }
      report.peak_held = std::max(report.peak_held, queue.size());
      queue.drain(write);
    }
    queue.flush(write);
  } catch (...) {
    stop_readers();
    throw;
  }
  stop_readers();
  // What was merged and how, after the messages (the duplicates are known only now).
  mcap::KeyValues meta{{"inputs", std::to_string(files.size())},
                       {"duplicates_dropped", std::to_string(report.duplicates_dropped)}};
  for (const auto& in : report.inputs) meta["host " + in.host] = in.file;
  for (const auto& [host, c] : clocks) {
    meta["offset_ns " + host] = std::to_string(c.offset_ns());
    meta["drift_ppm " + host] = std::to_string(c.drift_ppm());
  }
  for (const auto& [host, n] : report.ticks_acked_by_host) meta["ticks_acked " + host] = std::to_string(n);
  bag.write_metadata("merge", meta);
  bag.close();
  return report;
}

}  // namespace skelgraph::recording
