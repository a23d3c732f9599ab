#pragma once
// Constant-velocity Kalman filter for one joint in 3-D (state: position,
// velocity). Time passed in; measurements with their own noise; a gate on the
// Mahalanobis distance of each measurement to the prediction.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace skelgraph::fusion {

class JointFilter {
 public:
  // accel_sigma: how hard the joint may accelerate (m/s^2), the process noise.
  explicit JointFilter(double accel_sigma = 4.0) : accel_sigma_(accel_sigma) {}

  bool initialised() const { return initialised_; }
  void reset(const Eigen::Vector3d& p, double sigma_m, std::int64_t t_ns);
  // Moves the state to t_ns (no-op for t at or before the state's time).
  void predict(std::int64_t t_ns);
  // The squared Mahalanobis distance of z (isotropic noise sigma_m) to the prediction.
  double mahalanobis2(const Eigen::Vector3d& z, double sigma_m) const;
  void update(const Eigen::Vector3d& z, double sigma_m);
  // Replaces the position (a constraint such as a bone length), keeping velocity and covariance.
  void set_position(const Eigen::Vector3d& p) { x_.head<3>() = p; }

  Eigen::Vector3d position() const { return x_.head<3>(); }
  Eigen::Vector3d velocity() const { return x_.tail<3>(); }
  double position_sigma() const;  // sqrt of the mean positional variance
  Eigen::Matrix3d position_covariance() const { return P_.topLeftCorner<3, 3>(); }
  std::int64_t time_ns() const { return t_ns_; }

 private:
  double accel_sigma_;
  bool initialised_ = false;
  std::int64_t t_ns_ = 0;
  Eigen::Matrix<double, 6, 1> x_ = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> P_ = Eigen::Matrix<double, 6, 6>::Identity();
};

}  // namespace skelgraph::fusion
