#pragma once
// The sync master's logic, without DDS: sessions and the tick schedule.
// Replaces the thesis's Winsock server (R = start, Q = stop, A = save tick).
// Time is passed in: `mono_ns` (a monotonic clock) schedules ticks, `stamp_ns`
// (wall clock) is what messages carry.

#include <cstdint>
#include <string>
#include <vector>

namespace skelgraph::sync {

struct SyncEvent {
  enum class Kind { Start, Stop, Tick };
  Kind kind = Kind::Tick;
  std::uint32_t session_id = 0;
  std::string label;
  std::uint64_t tick = 0;      // Tick: 1, 2, ...; Start: 0; Stop: the last tick sent
  std::int64_t stamp_ns = 0;   // master's wall clock when sent
  std::string request_id;      // the control request that caused a START/STOP
};

class SyncMasterCore {
 public:
  struct Config {
    std::int64_t tick_period_ns = 33'000'000;
    std::int64_t session_duration_ns = 0;  // 0: until stopped
    std::uint64_t max_catch_up = 30;       // ticks sent at once after a stall; older ones are skipped
  };

  explicit SyncMasterCore(Config config);

  // Starts a session; a running one is stopped first (its STOP comes first).
  std::vector<SyncEvent> start(const std::string& label, std::int64_t mono_ns, std::int64_t stamp_ns,
                               const std::string& request_id = {});
  // Stops the running session; nothing when idle.
  std::vector<SyncEvent> stop(std::int64_t stamp_ns, const std::string& request_id = {});
  // The ticks due by `mono_ns`, and a STOP when the session's duration is over.
  std::vector<SyncEvent> advance(std::int64_t mono_ns, std::int64_t stamp_ns);

  bool running() const { return running_; }
  std::uint32_t session_id() const { return session_id_; }
  const std::string& label() const { return label_; }
  std::uint64_t ticks_sent() const { return last_tick_; }
  std::uint64_t ticks_skipped() const { return skipped_; }
  std::uint32_t sessions_started() const { return sessions_; }
  const Config& config() const { return config_; }

 private:
  Config config_;
  bool running_ = false;
  std::uint32_t session_id_ = 0;
  std::string label_;
  std::int64_t start_mono_ns_ = 0;
  std::uint64_t last_tick_ = 0;
  std::uint64_t skipped_ = 0;
  std::uint32_t sessions_ = 0;
};

}  // namespace skelgraph::sync
