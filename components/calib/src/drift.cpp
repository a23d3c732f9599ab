#include "skelgraph/calib/drift.hpp"
#include "skelgraph/skeleton/stats.hpp"

#include <algorithm>
#include <cmath>


namespace skelgraph::calib {

DriftMonitor::DriftMonitor(DriftOptions options) : o_(std::move(options)) {}

PairDrift& DriftMonitor::pair(const std::string& a, const std::string& b) {
  for (auto& p : pairs_)
    if (p.a == a && p.b == b) return p;
  pairs_.push_back(PairDrift{a, b});
  state_.emplace_back();
  return pairs_.back();
}

void DriftMonitor::set_pose(const std::string& sensor, const Eigen::Isometry3d& world_from_sensor) {
  const auto it = poses_.find(sensor);
  if (it != poses_.end() && it->second.isApprox(world_from_sensor, 1e-12)) return;  // the same pose again
  poses_[sensor] = world_from_sensor;
  since_.erase(sensor);
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    if (pairs_[i].a != sensor && pairs_[i].b != sensor) continue;
    pairs_[i] = PairDrift{pairs_[i].a, pairs_[i].b};
    state_[i] = PairState{};
  }
  // Data already held count towards the new baseline only from now on.
  auto& d = data_[sensor];
  d.erase(std::remove_if(d.begin(), d.end(), [&](const TimedSkeleton& x) { return x.t_ns < now_ns_; }), d.end());
}

void DriftMonitor::add(const std::string& sensor, std::int64_t receive_ns, const skeleton::Skeleton& s) {
  auto& d = data_[sensor];
  // One sample a frame (the people of a frame share its stamp).
  if (s.stamp_ns != 0 && (d.empty() || d.back().skeleton.stamp_ns != s.stamp_ns)) clocks_[sensor].add(s.stamp_ns, receive_ns);
  d.push_back({receive_ns, s});
}

std::vector<TimedSkeleton> DriftMonitor::window(const std::string& sensor, std::int64_t from_ns) const {
  std::vector<TimedSkeleton> out;
  const auto it = data_.find(sensor);
  if (it == data_.end()) return out;
  const auto clock = clocks_.find(sensor);
  for (const auto& x : it->second) {
    const std::int64_t t = x.skeleton.stamp_ns != 0 && clock != clocks_.end() ? clock->second.to_receive(x.skeleton.stamp_ns) : x.t_ns;
    if (t >= from_ns && t <= now_ns_) out.push_back({t, x.skeleton});
  }
  std::sort(out.begin(), out.end(), [](const TimedSkeleton& x, const TimedSkeleton& y) { return x.t_ns < y.t_ns; });
  return out;
}

void DriftMonitor::update(std::int64_t now_ns) {
  now_ns_ = now_ns;
  const auto window_ns = static_cast<std::int64_t>(o_.window_s * 1e9);
  const auto settle_ns = static_cast<std::int64_t>(o_.settle_s * 1e9);
  // Keep what the longest window can still use.
  for (auto& [id, d] : data_) {
    const std::int64_t keep = now_ns - std::max(window_ns, settle_ns) - 1'000'000'000;
    while (!d.empty() && d.front().t_ns < keep) d.pop_front();
  }
  for (auto a = poses_.begin(); a != poses_.end(); ++a) {
    for (auto b = std::next(a); b != poses_.end(); ++b) {
      PairDrift& p = pair(a->first, b->first);
      PairState& st = state_[static_cast<std::size_t>(&p - pairs_.data())];
      const bool baseline_due = !p.has_baseline && st.start_ns >= 0 && now_ns - st.start_ns >= settle_ns;
      const std::int64_t from = baseline_due ? st.start_ns : now_ns - window_ns;
      const auto c = correspondences(window(a->first, from), window(b->first, from), a->second.inverse() * b->second, o_.pairing);
      p.evaluated = c.reference.size() >= o_.min_pairs;
      p.pairs = c.reference.size();
      if (!p.evaluated) continue;
      if (st.start_ns < 0) {
        st.start_ns = now_ns - window_ns;  // the baseline window starts with the first shared views
        continue;
      }
      // Each joint pair's offset, a's joint minus b's (world), by the floor square the joint is over.
      std::map<std::pair<int, int>, std::vector<Eigen::Vector3d>> by_square;
      for (std::size_t q = 0; q < c.reference.size(); ++q) {
        const Eigen::Vector3d at = a->second * c.reference[q];
        const std::pair<int, int> square{static_cast<int>(std::floor(at.x() / o_.cell_m)),
                                         static_cast<int>(std::floor(at.z() / o_.cell_m))};
        by_square[square].push_back(at - b->second * c.other[q]);
      }
      const auto axis_median = [](const std::vector<Eigen::Vector3d>& v) {
        Eigen::Vector3d m;
        for (int k = 0; k < 3; ++k) {
          std::vector<double> x;
          for (const auto& d : v) x.push_back(d[k]);
          m[k] = stats::upper_median(x);
        }
        return m;
      };
      if (!p.has_baseline) {
        if (baseline_due) {
          for (const auto& [square, v] : by_square) st.baseline[square] = axis_median(v);
          p.has_baseline = true;
        }
        continue;
      }
      // The offsets beyond the baseline of their square (squares the baseline never saw are left out).
      std::vector<Eigen::Vector3d> beyond;
      for (const auto& [square, v] : by_square) {
        const auto base = st.baseline.find(square);
        if (base == st.baseline.end()) continue;
        for (const auto& d : v) beyond.push_back(d - base->second);
      }
      p.evaluated = beyond.size() >= o_.min_pairs;
      if (!p.evaluated) continue;
      p.change = axis_median(beyond);
      p.shift_cm = 100.0 * p.change.norm();
      p.streak = p.shift_cm >= o_.alarm_cm ? p.streak + 1 : 0;
    }
  }
  // A sensor reported stays reported until it gets a new pose: it was moved, and the offset
  // wandering back under the alarm does not put it back.
  for (const auto& s : sensors())
    if (s.drifted && !since_.count(s.id)) since_[s.id] = now_ns;
}

std::vector<SensorDrift> DriftMonitor::sensors() const {
  std::vector<SensorDrift> out;
  const auto is_off = [&](const PairDrift& p) { return p.has_baseline && p.streak >= o_.confirm; };
  for (const auto& [id, pose] : poses_) {
    SensorDrift s;
    s.id = id;
    s.refined = pose;
    bool all_off = true, any_off = false, other_fine = false;
    const PairDrift* best = nullptr;
    for (const auto& p : pairs_) {
      if (!p.has_baseline || !poses_.count(p.a) || !poses_.count(p.b)) continue;
      const bool mine = p.a == id || p.b == id;
      if (!mine) {
        // Within the alarm now, not merely unconfirmed: when a sensor moves, its pairs go off one
        // evaluation apart, and a third sensor whose other pair is off by noise must not be taken
        // for it while the moved one's pair is still confirming.
        other_fine = other_fine || p.streak == 0;
        continue;
      }
      if (!p.evaluated) continue;
      all_off = all_off && is_off(p);
      any_off = any_off || is_off(p);
      if (best == nullptr || p.pairs > best->pairs) best = &p;
    }
    const auto since = since_.find(id);
    s.drifted = (any_off && all_off && (poses_.size() == 2 || other_fine)) || since != since_.end();
    if (best != nullptr) {
      s.shift_cm = best->shift_cm;
      // The change is a's joints minus b's beyond the baseline: b's skeletons move by it, a's against it.
      s.refined = Eigen::Translation3d(best->b == id ? best->change : Eigen::Vector3d(-best->change)) * pose;
    }
    if (since != since_.end()) s.since_ns = since->second;
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace skelgraph::calib
