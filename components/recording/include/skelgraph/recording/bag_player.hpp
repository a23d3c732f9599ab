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
//
// A player of recordings (runtime::PlayerLink): pause, resume, step (by
// messages), speed and seek (seconds from the start) on skelgraph/play/control;
// its state, with position and duration, on skelgraph/play/state (also every
// 0.25 s while playing). A seek republishes, without waiting, the latest
// messages of the transient-local topics before the new position (sensor
// poses, the sync session) so late state is right, and skips the others.
// `hold_at_end` keeps the player at the end of the recording, waiting for a
// seek, instead of finishing (`skelgraph view`).

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
#include "skelgraph/runtime/player_link.hpp"
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
  bool finite() const override { return !loop_ && !hold_at_end_; }
  bool finished() const override { return done_; }

 private:
  struct Stopped {};
  struct SeekTo {
    std::uint64_t log_time;
  };
  void run();
  void wait_for_readers();
  // One pass from `from` (log time); messages before it: state topics published at once, others skipped.
  void play_once(std::uint64_t from);
  void dispose_idle(std::int64_t before_log_ns);
  // Sleeps until `log_time` is due on the playback clock (paused: until resumed or
  // stepped); throws Stopped when asked to stop, SeekTo when asked to seek.
  bool wait_until_due(std::uint64_t log_time);  // true: let through as a step
  void check_stop_and_seek();
  runtime::PlayerLink::Progress progress() const;

  std::string file_;
  double rate_;
  bool loop_;
  bool hold_at_end_;
  std::int64_t wait_ns_;
  std::uint64_t reorder_ns_;
  std::int64_t gone_after_ns_;
  std::uint64_t last_idle_check_ = 0;  // log time of the last dispose_idle (player thread)
  mcap::Reader reader_;
  std::uint64_t first_log_time_ = 0;
  std::uint64_t per_pass_ = 0;  // messages selected for playback in one pass
  std::map<std::uint16_t, std::size_t> publisher_of_channel_;  // channel id -> index in publishers_
  std::map<std::uint16_t, std::string> older_schema_;  // channels that may hold an older schema: their type
  std::vector<std::unique_ptr<runtime::RawPublisher>> publishers_;
  std::vector<std::string> publisher_topics_;
  std::vector<bool> publisher_is_state_;  // transient-local topics: replayed up to a seek's position
  std::uint64_t last_log_time_ = 0;
  std::atomic<std::uint64_t> position_log_{0};  // log time of the last message published
  std::atomic<bool> at_end_{false};
  std::int64_t pace_mono_ = 0;     // the playback clock: pace_mono_ <-> pace_log_
  std::uint64_t pace_log_ = 0;
  std::int64_t last_state_ns_ = 0;
  std::unique_ptr<runtime::PlayerLink> player_;
  std::atomic<std::uint64_t> published_{0}, failed_{0}, loops_{0}, reordered_late_{0};
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace skelgraph::recording
