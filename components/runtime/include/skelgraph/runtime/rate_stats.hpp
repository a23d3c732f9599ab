#pragma once
// Rate and period statistics over a sliding time window, from arrival times
// passed in (no clock inside). Used by `topic hz`, status reports and tests.

#include <cstddef>
#include <cstdint>
#include <deque>

#include <nlohmann/json.hpp>

namespace skelgraph::runtime {

struct RateSummary {
  std::size_t samples = 0;   // arrivals inside the window
  double rate_hz = 0.0;      // (samples - 1) / (last - first)
  double mean_period_s = 0.0;
  double min_period_s = 0.0;
  double max_period_s = 0.0;
  double std_period_s = 0.0;
};

class RateStats {
 public:
  // window_ns <= 0 keeps every arrival.
  explicit RateStats(std::int64_t window_ns = 0) : window_ns_(window_ns) {}
  void add(std::int64_t t_ns);
  // Drops arrivals older than the window before `now_ns`.
  void expire(std::int64_t now_ns);
  RateSummary summary() const;
  std::uint64_t total() const { return total_; }

 private:
  std::int64_t window_ns_;
  std::deque<std::int64_t> times_;
  std::uint64_t total_ = 0;
};

// Percentiles of a measured quantity (e.g. compute time per step): the
// latest `keep` values, plus the count and the maximum of all of them.
class Percentiles {
 public:
  explicit Percentiles(std::size_t keep = 4096) : keep_(keep) {}
  void add(double v);
  std::uint64_t count() const { return count_; }
  double max() const { return max_; }
  // q in [0, 1] over the values kept (nearest rank); 0 when empty.
  double quantile(double q) const;
  // {"n", "p50", "p99", "max"}
  nlohmann::json json() const;

 private:
  std::size_t keep_;
  std::deque<double> recent_;
  std::uint64_t count_ = 0;
  double max_ = 0.0;
};

}  // namespace skelgraph::runtime
