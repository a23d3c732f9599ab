#pragma once
// The skeleton calibration of a whole simulated cell, checked against the
// simulator's truth (`skelgraph calib sim`): every sensor's skeletons of a
// run calibrated at once (calibrate_cell) against the first sensor, each
// sensor's pose error, the same sensor calibrated against the reference alone
// (the pair method) for comparison, and optionally the floor: the rigid pose
// the skeletons themselves favour, searched from the truth. No DDS.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "skelgraph/calib/cell_calib.hpp"
#include "skelgraph/calib/skeleton_calib.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::calib {

// How far an estimated pose is from the true one.
struct PoseError {
  double deg = 0;  // rotation
  double cm = 0;   // translation
};
PoseError pose_error(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);

struct SimSensorCheck {
  std::string sensor;
  std::size_t frames = 0;
  bool placed = false;
  CellSensor fit;                   // the cell's solution for it (when placed)
  PoseError error;                  // ... against the truth
  std::optional<CellLink> pair;     // the link reference -> sensor, on its own
  PoseError pair_error;             // ... against the truth (when solved)
  std::optional<LowestMedian> floor;
  PoseError floor_error;
};

struct SimCellCheck {
  std::string reference;
  std::string error;                    // the cell could not be calibrated (why); nothing else then
  std::vector<SimSensorCheck> sensors;  // every sensor but the reference, in the layout's order
  PoseError worst;                      // over the placed sensors
  bool all_placed = true;
  bool within(double deg, double cm) const { return error.empty() && all_placed && worst.deg <= deg && worst.cm <= cm; }
};

// Runs `seconds` of the configured simulation and checks it.
SimCellCheck check_cell_calibration(const sim::SimConfig& config, double seconds, bool with_floor);

}  // namespace skelgraph::calib
