#include "skelgraph/skeleton/stamp_map.hpp"

#include <cmath>
#include <cstdlib>

namespace skelgraph::skeleton {

StampMap::StampMap(std::size_t window, std::int64_t jump_ns) : window_(window < 2 ? 2 : window), jump_ns_(jump_ns) {}

void StampMap::add(std::int64_t stamp_ns, std::int64_t receive_ns) {
  if (!samples_.empty() && std::llabs(to_receive(stamp_ns) - receive_ns) > jump_ns_) {
    samples_.clear();
    ++restarts_;
  }
  samples_.emplace_back(stamp_ns, receive_ns);
  while (samples_.size() > window_) samples_.pop_front();
  fit();
}

void StampMap::fit() {
  // Differences from the newest sample keep the sums small enough for doubles.
  origin_stamp_ = samples_.back().first;
  origin_receive_ = samples_.back().second;
  const double n = static_cast<double>(samples_.size());
  double sx = 0, sy = 0;
  for (const auto& [s, r] : samples_) {
    sx += static_cast<double>(s - origin_stamp_);
    sy += static_cast<double>(r - origin_receive_);
  }
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0;
  for (const auto& [s, r] : samples_) {
    const double dx = static_cast<double>(s - origin_stamp_) - mx;
    sxx += dx * dx;
    sxy += dx * (static_cast<double>(r - origin_receive_) - my);
  }
  // Stamps spanning under 100 ms cannot give a rate: one rate, the mean offset.
  slope_ = sxx > n * 1e16 ? sxy / sxx : 1.0;
  intercept_ = my - slope_ * mx;
}

std::int64_t StampMap::to_receive(std::int64_t stamp_ns) const {
  if (samples_.empty()) return stamp_ns;
  return origin_receive_ + std::llround(intercept_ + slope_ * static_cast<double>(stamp_ns - origin_stamp_));
}

}  // namespace skelgraph::skeleton
