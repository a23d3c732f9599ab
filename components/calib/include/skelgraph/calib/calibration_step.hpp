#pragma once
// One calibration step as every front end takes it: a fit on the data given,
// then the one acceptance policy. A new pose replaces the one before only
// when it brings the sensors' skeletons closer on the data the fit saw (the
// upper median of their joint distances), and never when the fit could not
// tell on which side of the person the sensor is (undecided). `skelgraph
// calib skeleton` (a pair, or the whole cell) goes through it. With a
// hold-out split (fit on the first half in time, check on the second) a step
// is judged on data it did not see.
// The drift component's refined pose is not judged this way: it corrects a
// pair's offset beyond its baseline, and on the simulator (a sensor moved
// 5 cm) the raw distances on the pair's last window rose 11.0 -> 11.7 cm while
// the pose came from 5.0 to 0.6 cm of the truth: the trackers' own
// view-dependent disagreement swamps a small correction. No DDS.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "skelgraph/calib/cell_calib.hpp"
#include "skelgraph/calib/skeleton_calib.hpp"

namespace skelgraph::calib {

using SensorSkeletons = std::map<std::string, std::vector<TimedSkeleton>>;
using SensorPoses = std::map<std::string, Eigen::Isometry3d>;

// Matches farther apart than this (median over joints) are other people.
inline constexpr double kAcceptanceMaxMatchM = 2.0;

struct Halves {
  SensorSkeletons fit, test;
};
// Every sensor's skeletons split in time at the middle of the reference's:
// before it to fit, from it on to check. Throws CalibError when the
// reference has none.
Halves split_halves(const SensorSkeletons& data, const std::string& reference);

// The upper median distance between one sensor's skeletons and every other
// sensor's under `poses` (all in one frame, e.g. reference_from_sensor), over
// `joints` (empty: all); NaN when none match.
double cell_median(const SensorSkeletons& data, const std::string& sensor, const SensorPoses& poses,
                   const std::vector<skeleton::JointId>& joints = {});

struct Acceptance {
  double before_m = std::nan("");  // the data's distance under the pose before
  double after_m = std::nan("");   // ... under the candidate
  bool undecided = false;          // the fit could not tell the sides apart: never taken
  bool improved = false;           // the candidate is taken
};
// The policy itself: taken when decided and closer than before (a NaN
// before, no match at all under the old pose, is beaten by any distance).
Acceptance accept(double before_m, double after_m, bool undecided);
// For a pair: distances of `other`'s skeletons to `reference`'s under each
// pose (reference_from_other); the candidate with its clock offset.
Acceptance accept_pose(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                       const Eigen::Isometry3d& before, const Eigen::Isometry3d& candidate,
                       std::int64_t candidate_offset_ns = 0, bool undecided = false);

struct PairStep {
  SkeletonCalibResult fit;  // reference_from_other as fitted
  Acceptance acceptance;
  Eigen::Isometry3d chosen = Eigen::Isometry3d::Identity();  // the fit when taken, else `before`
  std::int64_t chosen_offset_ns = 0;
};
// Fits `other` against `reference` and applies the policy. Throws CalibError.
PairStep calibrate_pair_step(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                             const Eigen::Isometry3d& before, const SkeletonCalibOptions& options = {});

struct CellStep {
  CellCalibResult fit;
  std::map<std::string, Acceptance> acceptance;  // every placed sensor but the reference
  SensorPoses chosen;                            // the fit where taken, `before` elsewhere
};
// Every sensor at once against `reference`; `before` holds the poses before
// (reference_from_sensor; a sensor missing there starts at the identity).
// Throws CalibError.
CellStep calibrate_cell_step(const SensorSkeletons& data, const std::string& reference, const SensorPoses& before,
                             const CellCalibOptions& options = {});

}  // namespace skelgraph::calib
