#pragma once
// What a listener on the sync topic saw, per session: START/STOP, how many
// ticks, gaps in the tick sequence, and the tick rate at arrival. DDS-free.

#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/runtime/rate_stats.hpp"

namespace skelgraph::monitor {

struct SessionObservation {
  std::uint32_t session_id = 0;
  std::string label;
  bool saw_start = false;
  bool saw_stop = false;
  std::uint64_t ticks = 0;          // TICKs received
  std::uint64_t first_tick = 0;
  std::uint64_t last_tick = 0;
  std::uint64_t missing_ticks = 0;  // gaps in the tick indices
  std::uint64_t stop_tick = 0;      // the last tick the master says it sent
  double master_rate_hz = 0.0;      // ticks per second by the master's own stamps
  runtime::RateSummary arrival;     // at this listener (bursts when it joins late, jitter)
};

class SyncWatch {
 public:
  enum class Kind { Start, Stop, Tick };
  void on_command(Kind kind, std::uint32_t session_id, const std::string& label, std::uint64_t tick,
                  std::int64_t master_stamp_ns, std::int64_t receive_ns);
  std::vector<SessionObservation> sessions() const;

 private:
  struct Entry {
    SessionObservation obs;
    runtime::RateStats rate{0};
    std::int64_t first_stamp_ns = 0;
    std::int64_t last_stamp_ns = 0;
  };
  Entry& entry(std::uint32_t session_id, const std::string& label);
  std::vector<Entry> entries_;
};

}  // namespace skelgraph::monitor
