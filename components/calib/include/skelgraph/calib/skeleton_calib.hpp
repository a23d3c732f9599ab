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
// 3. Under the best pose every reference person gets its match; a match that
//    fits better swapped (one sensor sees the back and, assuming the person
//    faces it, swapped the sides) is paired with its sides swapped back;
//    matches that fit badly (a different person, a ghost) are rejected. The
//    joint pairs left within the threshold are solved by
//    weighted SVD (Cauchy weights on the residuals: a joint hidden behind the
//    body but still claimed pulls less); pairing and solving repeat until the
//    pose settles.
//
// Everything is in the sensors' own frames; the result maps the other
// sensor's frame into the reference sensor's.

#include <cstdint>
#include <optional>
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
  // reference_from_other roughly known (a previous calibration, a measured
  // layout): decides between the pose and its rival turned round about the
  // person when the skeletons cannot (the one nearer in rotation is kept).
  std::optional<Eigen::Isometry3d> prior;
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
  std::size_t mirrored = 0;          // ... of them with the sides swapped (one sensor sees the back)
  std::size_t pairs = 0, inliers = 0;  // joint pairs solved, within the threshold
  std::vector<JointResidual> per_joint;
  // The rival pose, turned by 180 degrees about the person, solved too: its
  // inlier pairs. Ambiguous when within 5 % of this pose's, or when the person
  // hardly moved about (person_spread_m, the RMS distance of the reference's
  // torsos from their mean, under 15 cm): a body turned round looks like its
  // mirror image, so a person turning on the spot cannot tell on which side
  // of them a sensor is; walking about can.
  std::size_t turned_inliers = 0;
  double person_spread_m = 0;
  bool ambiguous = false;
  bool resolved_by_prior = false;  // ambiguous, and the prior chose
};

// Throws CalibError when there is nothing to solve (no overlap in time, no
// consistent pose), naming what was missing.
SkeletonCalibResult calibrate_from_skeletons(const std::vector<TimedSkeleton>& reference,
                                             const std::vector<TimedSkeleton>& other,
                                             const SkeletonCalibOptions& options = {});

// The joint pairs two sensors' skeletons give under a pose (each reference
// skeleton with its best-fitting match of the other sensor, as labelled or
// with the sides swapped; pairs within the inlier threshold).
struct Correspondences {
  std::vector<Eigen::Vector3d> reference, other;
  std::vector<bool> mirrored_pair;     // per pair: from a match with the sides swapped
  std::size_t matched = 0, mirrored = 0;
};
Correspondences correspondences(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                const Eigen::Isometry3d& reference_from_other, const SkeletonCalibOptions& options = {});

// For checking a pose on data it was not fitted to: every reference
// skeleton's nearest skeleton of the other sensor (under `reference_from_other`,
// interpolated to the same time; as labelled or with its sides swapped,
// whichever is nearer: a view of the back), and the distance of each of
// `joints` (both at confidence 1) between them, m. Matches farther than `max_match_m`
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


}  // namespace skelgraph::calib
