#pragma once
// Sensor extrinsics from the skeletons two sensors report of the same
// people at the same time — no board: walk around in front of both for 30 s.
//
// 1. The other sensor's skeletons are interpolated to each reference frame's
//    time (shifted by a clock offset, searched when asked for).
// 2. Which of its people is which of the reference's is not trusted to ids:
//    a RANSAC over single frames proposes a pose from one frame's joints; it
//    is scored by how many joints of all frames it brings within the
//    threshold, each reference person taking the other sensor's person (as
//    seen, or left/right swapped) that fits best.
// 3. Under the best pose every reference person gets its match; frames whose
//    match fits better swapped (one sensor sees the back and flipped the
//    sides) are rejected, as are matches that fit badly (a different person,
//    a ghost). The joint pairs left within the threshold are solved by
//    weighted SVD (Cauchy weights on the residuals: a joint hidden behind the
//    body but still claimed pulls less); pairing and solving repeat until the
//    pose settles.
//
// Everything is in the sensors' own frames; the result maps the other
// sensor's frame into the reference sensor's.

#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/calib/rigid.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::calib {

struct TimedSkeleton {
  std::int64_t t_ns = 0;  // on its sensor's clock (or one shared clock)
  skeleton::Skeleton skeleton;
};

struct SkeletonCalibOptions {
  // Joints used (default: head, neck, torso, shoulders, elbows, hands, hips).
  std::vector<skeleton::JointId> joints;
  std::int64_t max_gap_ns = 70'000'000;          // interpolate only between frames this close
  std::int64_t max_clock_offset_ns = 0;          // search the other sensor's clock offset within +-this
  double inlier_threshold_m = 0.12;              // a joint pair agrees this well under a good pose
  double match_median_m = 0.20;                  // a person match whose median joint distance exceeds this is not one
  double robust_scale_m = 0.05;                  // Cauchy weights 1 / (1 + (r / this)^2) in the refits (0: none)
  int hypotheses = 300;                          // frame-level RANSAC samples
  std::size_t max_scored_frames = 1500;          // hypotheses are scored on at most this many frames (evenly spread)
  std::uint64_t seed = 1;
};

struct JointResidual {
  skeleton::JointId joint;
  std::size_t pairs = 0;       // inlier pairs of this joint
  double median_m = 0, rms_m = 0;
};

struct SkeletonCalibResult {
  Alignment fit;                  // reference_from_other (rigid)
  std::int64_t clock_offset_ns = 0;  // other's clock + offset = reference's clock
  std::size_t reference_frames = 0;  // reference skeletons (person-frames) considered
  std::size_t matched = 0;           // ... with a matching skeleton of the other sensor
  std::size_t flipped = 0;           // ... rejected as left/right swapped
  std::size_t pairs = 0, inliers = 0;  // joint pairs solved, within the threshold
  std::vector<JointResidual> per_joint;
};

// Throws CalibError when there is nothing to solve (no overlap in time, no
// consistent pose), naming what was missing.
SkeletonCalibResult calibrate_from_skeletons(const std::vector<TimedSkeleton>& reference,
                                             const std::vector<TimedSkeleton>& other,
                                             const SkeletonCalibOptions& options = {});

// For checking a pose on data it was not fitted to: every reference
// skeleton's nearest skeleton of the other sensor (under `reference_from_other`,
// interpolated to the same time), and the distance of each of `joints` (both
// at confidence 1) between them, m. Matches farther than `max_match_m`
// (median over joints) are other people and left out.
std::vector<double> joint_distances(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                    const Eigen::Isometry3d& reference_from_other, std::int64_t clock_offset_ns = 0,
                                    const std::vector<skeleton::JointId>& joints = {}, double max_match_m = 1.0,
                                    std::int64_t max_gap_ns = 70'000'000);

// The rigid pose near `start` with the lowest median of joint_distances()
// on the given data, by a local search (Nelder-Mead over a rotation vector
// and a translation applied on top of `start`, restarted twice from the best
// with smaller steps; deterministic). Run on the very data a calibration is
// scored on, it says what no rigid pose nearby can beat there: how much of
// the remaining disagreement is the pose and how much the trackers' own
// (a view-dependent placement no rigid transform removes).
// `starts` > 1 also searches from starts - 1 other poses around `start`
// (rotations of up to 10 degrees about random axes and shifts of up to
// 30 cm, from a fixed seed) and keeps the lowest: a median over matched
// joints has local minima, so one search alone could stop in one.
struct LowestMedian {
  Eigen::Isometry3d reference_from_other = Eigen::Isometry3d::Identity();
  double median_m = 0;       // at that pose
  double start_median_m = 0;  // at `start`
  int starts = 1;             // searches run
};
LowestMedian lowest_median_pose(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                const Eigen::Isometry3d& start, std::int64_t clock_offset_ns = 0,
                                const std::vector<skeleton::JointId>& joints = {}, double max_match_m = 1.0, int starts = 1);

double median(std::vector<double> v);  // NaN when empty

}  // namespace skelgraph::calib
