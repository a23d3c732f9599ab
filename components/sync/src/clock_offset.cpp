#include "skelgraph/sync/clock_offset.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace skelgraph::sync {

bool ClockOffsetEstimator::add(const ClockExchange& e) {
  if (e.delay() < 0 || e.t4 < e.t1 || e.t3 < e.t2) return false;
  exchanges_.push_back(e);
  while (exchanges_.size() > window_) exchanges_.pop_front();
  return true;
}

std::optional<ClockEstimate> ClockOffsetEstimator::estimate() const {
  if (exchanges_.empty()) return std::nullopt;
  std::int64_t best = exchanges_.front().delay();
  for (const auto& e : exchanges_) best = std::min(best, e.delay());
  const auto limit = static_cast<std::int64_t>(1.5 * static_cast<double>(best)) + 200'000;
  std::vector<const ClockExchange*> good;
  for (const auto& e : exchanges_) {
    if (e.delay() <= limit) good.push_back(&e);
  }
  ClockEstimate est;
  est.rtt_ns = best;
  est.samples = good.size();
  const auto t0 = good.front()->t1;
  const double span = static_cast<double>(good.back()->t1 - t0);
  if (good.size() >= 3 && span >= 2e9) {
    // Least squares: offset = a + b * (t1 - t0), in double around the first sample.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double y0 = static_cast<double>(good.front()->offset());
    for (const auto* e : good) {
      const double x = static_cast<double>(e->t1 - t0);
      const double y = static_cast<double>(e->offset()) - y0;
      sx += x;
      sy += y;
      sxx += x * x;
      sxy += x * y;
    }
    const double n = static_cast<double>(good.size());
    const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    const double a = (sy - b * sx) / n;
    est.drift_ppm = b * 1e6;
    est.offset_ns = static_cast<std::int64_t>(std::llround(y0 + a + b * static_cast<double>(exchanges_.back().t1 - t0)));
  } else {
    std::vector<std::int64_t> offsets;
    for (const auto* e : good) offsets.push_back(e->offset());
    std::nth_element(offsets.begin(), offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2), offsets.end());
    est.offset_ns = offsets[offsets.size() / 2];
  }
  return est;
}

}  // namespace skelgraph::sync
