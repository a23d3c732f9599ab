#include "skelgraph/calib/calibration_step.hpp"

#include <algorithm>

#include "skelgraph/skeleton/stats.hpp"

namespace skelgraph::calib {

Halves split_halves(const SensorSkeletons& data, const std::string& reference) {
  const auto it = data.find(reference);
  if (it == data.end() || it->second.empty()) throw CalibError("no skeletons of reference sensor '" + reference + "'");
  std::int64_t lo = it->second.front().t_ns, hi = lo;
  for (const auto& x : it->second) lo = std::min(lo, x.t_ns), hi = std::max(hi, x.t_ns);
  const std::int64_t mid = lo + (hi - lo) / 2;
  Halves h;
  for (const auto& [id, v] : data)
    for (const auto& x : v) (x.t_ns < mid ? h.fit[id] : h.test[id]).push_back(x);
  return h;
}

double cell_median(const SensorSkeletons& data, const std::string& sensor, const SensorPoses& poses,
                   const std::vector<skeleton::JointId>& joints) {
  if (!data.count(sensor) || !poses.count(sensor)) return std::nan("");
  std::vector<double> all;
  for (const auto& [t, v] : data) {
    if (t == sensor || !poses.count(t)) continue;
    const auto d = joint_distances(data.at(sensor), v, poses.at(sensor).inverse() * poses.at(t), 0, joints,
                                   kAcceptanceMaxMatchM);
    all.insert(all.end(), d.begin(), d.end());
  }
  return stats::upper_median(all);
}

Acceptance accept(double before_m, double after_m, bool undecided) {
  Acceptance a;
  a.before_m = before_m;
  a.after_m = after_m;
  a.undecided = undecided;
  a.improved = !undecided && !(after_m >= before_m);
  return a;
}

Acceptance accept_pose(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                       const Eigen::Isometry3d& before, const Eigen::Isometry3d& candidate,
                       std::int64_t candidate_offset_ns, bool undecided) {
  const double b = stats::upper_median(joint_distances(reference, other, before, 0, {}, kAcceptanceMaxMatchM));
  const double a =
      stats::upper_median(joint_distances(reference, other, candidate, candidate_offset_ns, {}, kAcceptanceMaxMatchM));
  return accept(b, a, undecided);
}

PairStep calibrate_pair_step(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                             const Eigen::Isometry3d& before, const SkeletonCalibOptions& options) {
  PairStep s;
  s.fit = calibrate_from_skeletons(reference, other, options);
  s.acceptance = accept_pose(reference, other, before, s.fit.fit.transform(), s.fit.clock_offset_ns,
                             s.fit.ambiguous && !s.fit.resolved_by_prior);
  s.chosen = s.acceptance.improved ? s.fit.fit.transform() : before;
  s.chosen_offset_ns = s.acceptance.improved ? s.fit.clock_offset_ns : 0;
  return s;
}

CellStep calibrate_cell_step(const SensorSkeletons& data, const std::string& reference, const SensorPoses& before,
                             const CellCalibOptions& options) {
  CellStep s;
  s.fit = calibrate_cell(data, reference, options);
  SensorPoses old, fitted;
  for (const auto& [id, v] : data) {
    const auto b = before.find(id);
    old[id] = b != before.end() ? b->second : Eigen::Isometry3d::Identity();
  }
  fitted = old;
  for (const auto& c : s.fit.sensors)
    if (c.placed) fitted[c.id] = c.reference_from_sensor;
  s.chosen = old;
  for (const auto& c : s.fit.sensors) {
    if (c.id == reference || !c.placed) continue;
    // Sensor by sensor, against every other sensor where it stood before.
    auto& a = s.acceptance[c.id] = accept(cell_median(data, c.id, old), cell_median(data, c.id, fitted), c.ambiguous);
    if (a.improved) s.chosen[c.id] = fitted[c.id];
  }
  return s;
}

}  // namespace skelgraph::calib
