#include "skelgraph/skeleton/skeleton.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace skelgraph::skeleton {

namespace {
constexpr const char* kNames[kJointCount] = {"head",       "neck",          "torso",       "left_shoulder",
                                              "left_elbow", "left_hand",     "right_shoulder", "right_elbow",
                                              "right_hand", "left_hip",      "left_knee",   "left_foot",
                                              "right_hip",  "right_knee",    "right_foot"};
}  // namespace

const char* joint_name(JointId id) {
  const auto i = static_cast<std::size_t>(id);
  return i < kJointCount ? kNames[i] : "unknown";
}

std::optional<JointId> joint_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kJointCount; ++i) {
    if (name == kNames[i]) return joint_at(i);
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> claimed_facing(const Skeleton& s, const Eigen::Vector3d& up) {
  const auto& l = s[JointId::LeftShoulder];
  const auto& r = s[JointId::RightShoulder];
  if (l.confidence <= 0 || r.confidence <= 0) return std::nullopt;
  // Right-handed: left = up x forward, so forward = left x up.
  const Eigen::Vector3d f = (l.position - r.position).cross(up);
  if (!(f.norm() > 1e-6)) return std::nullopt;
  return Eigen::Vector3d(f.normalized());
}

double radius_95(const Joint& j) {
  if (!has_covariance(j)) return 0.0;
  const double largest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance_of(j), Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  return largest > 0.0 ? std::sqrt(7.815 * largest) : 0.0;
}

Eigen::Matrix3d covariance_of(const Joint& j) {
  const auto& c = j.covariance;
  Eigen::Matrix3d m;
  m << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
  return m;
}

void set_covariance(Joint& j, const Eigen::Matrix3d& c) {
  j.covariance = {static_cast<float>(c(0, 0)), static_cast<float>(c(0, 1)), static_cast<float>(c(0, 2)),
                  static_cast<float>(c(1, 1)), static_cast<float>(c(1, 2)), static_cast<float>(c(2, 2))};
}

std::optional<Eigen::Vector3d> centre_of(const skeleton::Skeleton& s) {
  const auto& torso = s[JointId::Torso];
  if (torso.confidence > 0) return torso.position;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& j : s.joints) {
    if (j.confidence <= 0) continue;
    sum += j.position;
    ++n;
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

JointId mirror(JointId id) {
  switch (id) {
    case JointId::LeftShoulder: return JointId::RightShoulder;
    case JointId::LeftElbow: return JointId::RightElbow;
    case JointId::LeftHand: return JointId::RightHand;
    case JointId::LeftHip: return JointId::RightHip;
    case JointId::LeftKnee: return JointId::RightKnee;
    case JointId::LeftFoot: return JointId::RightFoot;
    case JointId::RightShoulder: return JointId::LeftShoulder;
    case JointId::RightElbow: return JointId::LeftElbow;
    case JointId::RightHand: return JointId::LeftHand;
    case JointId::RightHip: return JointId::LeftHip;
    case JointId::RightKnee: return JointId::LeftKnee;
    case JointId::RightFoot: return JointId::LeftFoot;
    default: return id;
  }
}

void swap_sides(Skeleton& s) {
  const auto copy = s.joints;
  for (std::size_t j = 0; j < kJointCount; ++j) s.joints[j] = copy[static_cast<std::size_t>(mirror(joint_at(j)))];
}

}  // namespace skelgraph::skeleton
