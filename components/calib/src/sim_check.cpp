#include "skelgraph/calib/sim_check.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "skelgraph/calib/rigid.hpp"

namespace skelgraph::calib {

PoseError pose_error(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return {rotation_angle_deg(estimate.linear() * truth.linear().transpose()),
          100.0 * (estimate.translation() - truth.translation()).norm()};
}

SimCellCheck check_cell_calibration(const sim::SimConfig& cfg, double seconds, bool with_floor) {
  sim::Simulation simulation(cfg);
  std::map<std::string, std::vector<TimedSkeleton>> by_sensor;
  for (auto& e : simulation.advance(seconds)) {
    if (e.kind != sim::SimEvent::Kind::Raw) continue;
    by_sensor[cfg.sensors[e.sensor].id].push_back({static_cast<std::int64_t>(std::llround(e.t * 1e9)), std::move(e.skeleton)});
  }
  SimCellCheck out;
  out.reference = cfg.sensors.front().id;
  const Eigen::Isometry3d world_from_ref = cfg.sensors.front().world_from_sensor();
  CellCalibResult r;
  try {
    r = calibrate_cell(by_sensor, out.reference);
  } catch (const CalibError& e) {
    out.error = e.what();
    out.all_placed = false;
    return out;
  }
  for (const auto& c : cfg.sensors) {
    if (c.id == out.reference) continue;
    const Eigen::Isometry3d truth = world_from_ref.inverse() * c.world_from_sensor();
    SimSensorCheck s;
    s.sensor = c.id;
    s.frames = by_sensor.count(c.id) ? by_sensor.at(c.id).size() : 0;
    const auto* fit = r.sensor(c.id);
    s.placed = fit != nullptr && fit->placed;
    if (!s.placed) {
      out.all_placed = false;
      out.sensors.push_back(std::move(s));
      continue;
    }
    s.fit = *fit;
    s.error = pose_error(fit->reference_from_sensor, truth);
    out.worst.deg = std::max(out.worst.deg, s.error.deg);
    out.worst.cm = std::max(out.worst.cm, s.error.cm);
    for (const auto& l : r.links) {
      if (l.a != out.reference || l.b != c.id) continue;
      s.pair = l;
      if (l.solved) s.pair_error = pose_error(l.fit.fit.transform(), truth);
    }
    if (with_floor && by_sensor.count(c.id)) {
      s.floor = lowest_median_pose(by_sensor.at(out.reference), by_sensor.at(c.id), truth, 0, {}, 2.0);
      s.floor_error = pose_error(s.floor->reference_from_other, truth);
    }
    out.sensors.push_back(std::move(s));
  }
  return out;
}

}  // namespace skelgraph::calib
