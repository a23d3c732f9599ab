#include "skelgraph/fusion/joint_filter.hpp"

#include <cmath>

namespace skelgraph::fusion {

void JointFilter::reset(const Eigen::Vector3d& p, double sigma_m, std::int64_t t_ns) {
  x_.setZero();
  x_.head<3>() = p;
  P_.setZero();
  P_.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * sigma_m * sigma_m;
  P_.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * 1.0;  // up to ~1 m/s unknown
  t_ns_ = t_ns;
  initialised_ = true;
}

void JointFilter::predict(std::int64_t t_ns) {
  if (!initialised_ || t_ns <= t_ns_) return;
  const double dt = static_cast<double>(t_ns - t_ns_) * 1e-9;
  t_ns_ = t_ns;
  Eigen::Matrix<double, 6, 6> F = Eigen::Matrix<double, 6, 6>::Identity();
  F.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * dt;
  // Piecewise-constant white acceleration.
  const double q = accel_sigma_ * accel_sigma_;
  Eigen::Matrix<double, 6, 6> Q = Eigen::Matrix<double, 6, 6>::Zero();
  Q.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * std::pow(dt, 4) / 4);
  Q.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * std::pow(dt, 3) / 2);
  Q.bottomLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * std::pow(dt, 3) / 2);
  Q.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * dt * dt);
  x_ = F * x_;
  P_ = F * P_ * F.transpose() + Q;
}

double JointFilter::mahalanobis2(const Eigen::Vector3d& z, double sigma_m) const {
  const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + Eigen::Matrix3d::Identity() * sigma_m * sigma_m;
  const Eigen::Vector3d y = z - x_.head<3>();
  return y.dot(S.ldlt().solve(y));
}

void JointFilter::update(const Eigen::Vector3d& z, double sigma_m) {
  const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + Eigen::Matrix3d::Identity() * sigma_m * sigma_m;
  const Eigen::Matrix<double, 6, 3> K = P_.leftCols<3>() * S.inverse();
  x_ += K * (z - x_.head<3>());
  Eigen::Matrix<double, 6, 6> I_KH = Eigen::Matrix<double, 6, 6>::Identity();
  I_KH.leftCols<3>() -= K;
  P_ = I_KH * P_;
  P_ = 0.5 * (P_ + P_.transpose());
}

double JointFilter::position_sigma() const { return std::sqrt(P_.topLeftCorner<3, 3>().trace() / 3.0); }

}  // namespace skelgraph::fusion
