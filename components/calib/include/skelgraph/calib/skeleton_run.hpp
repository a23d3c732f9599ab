#pragma once
// One input calibrated from its skeletons (`skelgraph calib skeleton`), as a
// report: a pair (the reference and one other sensor) or the whole cell at
// once, fitted on everything or on the first half with the second held out,
// each sensor's pose, residuals, per-joint figures, the never-worse
// acceptance (calibration_step.hpp) and a verdict in words; the report is
// what `--json` prints.

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "skelgraph/calib/inputs.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::calib {

// A pose as the reports give it: translation_m, rotation_xyzw, rotation_deg.
nlohmann::json pose_json(const Eigen::Isometry3d& T);
// Metres to centimetres, rounded to the millimetre (non-finite stays so).
double cm(double m);

struct SkeletonRun {
  std::string ref;    // the reference sensor
  std::string other;  // the one other sensor; empty: the only other one, or the whole cell if more
  double threshold_m = 0.12, robust_scale_m = 0.05, clock_search_ms = 0;
  bool holdout = false;    // fit on the first half, check on the second
  bool best_rigid = false;  // with holdout: the best rigid pose for the held-out half itself (the floor)
  int best_rigid_starts = 1;
};

// `in.poses`: the poses the input already implies (the previous ones; none:
// a shared frame). Returns the report; `results` gets each calibrated
// sensor's pose in the reference's frame (method "skeleton", "skeleton
// (cell)" or "unchanged"). Throws InputError naming `path` (no skeletons of
// a sensor asked for, a fit that cannot be made).
nlohmann::json calibrate_skeletons(const std::string& path, const SkeletonInput& in, const SkeletonRun& o,
                                   std::vector<skeleton::SensorPose>* results);

}  // namespace skelgraph::calib
