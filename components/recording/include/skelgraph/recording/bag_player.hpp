#pragma once
// `bag_player` component: republishes a recording's messages with their
// original timing (log time; a multiple of it with `rate`), topics and keys,
// exactly as recorded (CDR as it was sent). Component status is not replayed
// (it would describe components that are not running).
//
// Streams: the file is mapped, one chunk at a time is decompressed, and a
// playback thread publishes each message when it is due, so memory does not
// grow with the recording (depth recordings are GBs). Messages a little out of
// order in the file (within `reorder_s`) are put back in log-time order.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::recording {

class BagPlayer final : public runtime::Component {
 public:
  BagPlayer(runtime::Context& ctx, const runtime::Params& params);
  ~BagPlayer() override;
  static runtime::ComponentInfo describe();
  void on_start() override;
  void on_shutdown() override;
  std::string summary() const override;
  nlohmann::json details() const override;
  bool finite() const override { return !loop_; }
  bool finished() const override { return done_; }

 private:
  struct Stopped {};
  void run();
  void wait_for_readers();
  void play_once();
  // Sleeps until `log_time` is due on the playback clock; throws Stopped when asked to stop.
  void wait_until_due(std::uint64_t log_time);

  std::string file_;
  double rate_;
  bool loop_;
  std::int64_t wait_ns_;
  std::uint64_t reorder_ns_;
  mcap::Reader reader_;
  std::uint64_t first_log_time_ = 0;
  std::uint64_t per_pass_ = 0;  // messages selected for playback in one pass
  std::map<std::uint16_t, std::size_t> publisher_of_channel_;  // channel id -> index in publishers_
  std::vector<std::unique_ptr<runtime::RawPublisher>> publishers_;
  std::vector<std::string> publisher_topics_;
  std::atomic<std::uint64_t> published_{0}, failed_{0}, loops_{0}, reordered_late_{0};
  std::int64_t start_mono_ns_ = 0;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace skelgraph::recording
