#pragma once
// Rigid (optionally similarity) alignment of two 3-D point sets: find R, t
// (and s) with b ≈ s R a + t. Closed form by SVD of the weighted
// cross-covariance (Kabsch; Umeyama for the scale), with the reflection case
// handled, and RANSAC around it for outliers. Eigen only, no I/O.

#include <cstdint>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

namespace skelgraph::calib {

// Input the alignment cannot use: too few points, points on a line, NaN,
// mismatched sizes, bad weights. The message says which.
class CalibError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct Alignment {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // Residuals |s R a_i + t - b_i| of the points fitted, m.
  std::vector<double> residuals;
  double rms = 0.0, max = 0.0;

  Eigen::Vector3d apply(const Eigen::Vector3d& a) const { return scale * (R * a) + t; }
  // b_from_a as a rigid transform (scale ignored: 1 for rigid fits).
  Eigen::Isometry3d transform() const;
};

struct AlignOptions {
  bool with_scale = false;  // Umeyama: also estimate a uniform scale
  // Relative size of the second singular value of the spread of `a` below
  // which the points count as collinear.
  double collinear_tolerance = 1e-6;
};

// Throws CalibError on degenerate input. `weights` empty: all 1; else one per
// point, >= 0, not all 0.
Alignment align(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                const std::vector<double>& weights = {}, const AlignOptions& options = {});

// Residuals of an alignment on other points (e.g. held-out ones).
std::vector<double> residuals(const Alignment& fit, const std::vector<Eigen::Vector3d>& a,
                              const std::vector<Eigen::Vector3d>& b);

struct RansacOptions {
  double inlier_threshold_m = 0.05;
  int max_iterations = 1000;
  double confidence = 0.999;       // stop early once a better model is this unlikely
  std::uint64_t seed = 1;          // deterministic
  std::size_t min_inliers = 3;     // fewer: CalibError ("no consistent subset")
  AlignOptions align;
};

struct RansacResult {
  Alignment fit;                    // refit on the inliers (residuals: of the inliers)
  std::vector<std::size_t> inliers;  // indices into a/b
  int iterations = 0;
};

// Minimal samples of 3 non-collinear pairs; the model with the most inliers
// (ties: lower inlier RMS) is refit on its inliers until the set is stable.
RansacResult ransac_align(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                          const RansacOptions& options = {});

// One pose from corresponding corner sets of several views (e.g. the same
// boards lifted in two cameras, or lifted in a camera and known in the
// world): all corners pooled, RANSAC (2 cm) then SVD on the inliers. Maps b's frame into a's.
RansacResult pose_from_views(const std::vector<std::vector<Eigen::Vector3d>>& a,
                             const std::vector<std::vector<Eigen::Vector3d>>& b);

// OpenCV camera frame (x right, y down, z forward) to skelgraph's sensor
// frames (the skeleton trackers': x left, y up, z forward): diag(-1, -1, 1).
Eigen::Matrix3d sensor_from_camera();

// Angle of a rotation, degrees.
double rotation_angle_deg(const Eigen::Matrix3d& R);

}  // namespace skelgraph::calib
