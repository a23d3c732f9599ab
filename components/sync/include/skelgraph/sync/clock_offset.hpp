#pragma once
// Each host's clock against the sync master's, from tick/ack exchanges, as NTP
// does it: the master sends a tick at t1 (its clock), the host receives it at
// t2 and answers at t3 (its clock), the master gets the answer at t4. Then
//   offset = ((t2 - t1) + (t3 - t4)) / 2     (host clock minus master clock)
//   delay  = (t4 - t1) - (t3 - t2)           (network round trip)
// and the error of an offset is at most half its delay, so exchanges with a
// short round trip are trusted. Drift is the slope of offset over time. DDS-free.

#include <cstdint>
#include <deque>
#include <optional>

namespace skelgraph::sync {

struct ClockExchange {
  std::int64_t t1, t2, t3, t4;  // ns
  std::int64_t offset() const { return ((t2 - t1) + (t3 - t4)) / 2; }
  std::int64_t delay() const { return (t4 - t1) - (t3 - t2); }
};

struct ClockEstimate {
  std::int64_t offset_ns = 0;  // at the latest exchange
  double drift_ppm = 0.0;
  std::int64_t rtt_ns = 0;     // the best round trip in the window
  std::size_t samples = 0;     // exchanges used
};

class ClockOffsetEstimator {
 public:
  explicit ClockOffsetEstimator(std::size_t window = 256) : window_(window) {}
  // Exchanges with a negative delay (clock read out of order) are ignored; returns whether it was used.
  bool add(const ClockExchange& e);
  // Nothing before the first exchange. Uses the exchanges whose round trip is
  // within 1.5x (+0.2 ms) of the best; fits the drift when they span 2 s or more.
  std::optional<ClockEstimate> estimate() const;
  std::size_t size() const { return exchanges_.size(); }

 private:
  std::size_t window_;
  std::deque<ClockExchange> exchanges_;
};

}  // namespace skelgraph::sync
