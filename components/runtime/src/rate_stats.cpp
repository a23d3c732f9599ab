#include "skelgraph/runtime/rate_stats.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace skelgraph::runtime {

void RateStats::add(std::int64_t t_ns) {
  times_.push_back(t_ns);
  ++total_;
  expire(t_ns);
}

void RateStats::expire(std::int64_t now_ns) {
  if (window_ns_ <= 0) return;
  while (!times_.empty() && times_.front() < now_ns - window_ns_) times_.pop_front();
}

RateSummary RateStats::summary() const {
  RateSummary s;
  s.samples = times_.size();
  if (times_.size() < 2) return s;
  double sum = 0.0, sum_sq = 0.0;
  double mn = 1e300, mx = 0.0;
  for (std::size_t i = 1; i < times_.size(); ++i) {
    const double p = static_cast<double>(times_[i] - times_[i - 1]) * 1e-9;
    sum += p;
    sum_sq += p * p;
    mn = std::min(mn, p);
    mx = std::max(mx, p);
  }
  const double n = static_cast<double>(times_.size() - 1);
  s.mean_period_s = sum / n;
  s.min_period_s = mn;
  s.max_period_s = mx;
  s.std_period_s = std::sqrt(std::max(0.0, sum_sq / n - s.mean_period_s * s.mean_period_s));
  s.rate_hz = s.mean_period_s > 0.0 ? 1.0 / s.mean_period_s : 0.0;
  return s;
}

void Percentiles::add(double v) {
  recent_.push_back(v);
  if (recent_.size() > keep_) recent_.pop_front();
  max_ = count_ == 0 ? v : std::max(max_, v);
  ++count_;
}

double Percentiles::quantile(double q) const {
  if (recent_.empty()) return 0.0;
  std::vector<double> v(recent_.begin(), recent_.end());
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

nlohmann::json Percentiles::json() const {
  return {{"n", count_}, {"p50", quantile(0.5)}, {"p99", quantile(0.99)}, {"max", max_}};
}

}  // namespace skelgraph::runtime
