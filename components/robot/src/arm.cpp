#include "skelgraph/robot/arm.hpp"

#include <algorithm>
#include <cmath>

namespace skelgraph::robot {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kGain = 4.0;        // 1/s: tool velocity asked per metre to go
constexpr double kDamping = 0.05;    // damped least squares, m
const char* const kSegmentNames[7] = {"base", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3", "tool"};

Eigen::Isometry3d dh_transform(const DhJoint& j, double theta) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  t.translate(Eigen::Vector3d(j.a, 0.0, j.d));
  t.rotate(Eigen::AngleAxisd(j.alpha, Eigen::Vector3d::UnitX()));
  return t;
}
}  // namespace

ArmModel ArmModel::ur5e() {
  ArmModel m;
  m.name = "UR5e";
  m.dh = {DhJoint{0.0, 0.1625, kPi / 2}, DhJoint{-0.425, 0.0, 0.0},      DhJoint{-0.3922, 0.0, 0.0},
          DhJoint{0.0, 0.1333, kPi / 2}, DhJoint{0.0, 0.0997, -kPi / 2}, DhJoint{0.0, 0.0996, 0.0}};
  m.max_speed = Joints::Constant(kPi);  // 180 deg/s
  m.max_accel = Joints::Constant(8.0);
  m.lower = Joints::Constant(-2 * kPi);
  m.upper = Joints::Constant(2 * kPi);
  m.upper(2) = kPi;  // the elbow turns +-180 deg
  m.lower(2) = -kPi;
  m.max_tool_speed = 1.0;
  m.tool_length = 0.10;
  m.radius = {0.080, 0.065, 0.055, 0.050, 0.045, 0.045, 0.040};
  return m;
}

std::array<Eigen::Isometry3d, 8> forward(const ArmModel& m, const Joints& q) {
  std::array<Eigen::Isometry3d, 8> f;
  f[0] = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) f[i + 1] = f[i] * dh_transform(m.dh[i], q(i));
  f[7] = f[6] * Eigen::Translation3d(0.0, 0.0, m.tool_length);
  return f;
}

Eigen::Matrix<double, 3, 6> position_jacobian(const ArmModel& m, const Joints& q) {
  const auto f = forward(m, q);
  const Eigen::Vector3d tip = f[7].translation();
  Eigen::Matrix<double, 3, 6> j;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d axis = f[i].linear().col(2);  // joint i+1 turns about z of frame i
    j.col(i) = axis.cross(tip - f[i].translation());
  }
  return j;
}

std::vector<Capsule> arm_capsules(const ArmModel& m, const Joints& q, const Eigen::Isometry3d& world_from_base) {
  const auto f = forward(m, q);
  std::vector<Capsule> out;
  for (int i = 0; i < 7; ++i) {
    out.push_back({world_from_base * f[i].translation(), world_from_base * f[i + 1].translation(),
                   m.radius[static_cast<std::size_t>(i)], kSegmentNames[i]});
  }
  return out;
}

Eigen::Isometry3d base_pose(double x, double y, double z, double yaw_deg) {
  // Base z (up) -> world y; base x -> world x; base y -> world -z; then the turn about the vertical.
  Eigen::Matrix3d up;
  up << 1, 0, 0,  //
      0, 0, 1,    //
      0, -1, 0;
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw_deg * kPi / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix() * up;
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

ArmSim::ArmSim(ArmModel model, Eigen::Isometry3d world_from_base, Joints start)
    : m_(std::move(model)), world_from_base_(world_from_base), q_(start) {}

void ArmSim::set_target(const Eigen::Vector3d& tool_world, double max_speed_m_s) {
  target_ = tool_world;
  target_speed_ = std::clamp(max_speed_m_s, 0.0, m_.max_tool_speed);
  has_target_ = true;
}

void ArmSim::clear_target() { has_target_ = false; }

void ArmSim::set_speed_scale(double s) { scale_ = std::clamp(s, 0.0, 1.0); }

void ArmSim::protective_stop() {
  if (stop_) return;
  stop_ = true;
  stop_elapsed_ = 0.0;
  stop_from_speed_ = tool_speed();
}

void ArmSim::resume() { stop_ = false; }

Eigen::Vector3d ArmSim::tool_world() const { return world_from_base_ * forward(m_, q_)[7].translation(); }

double ArmSim::tool_speed() const { return (position_jacobian(m_, q_) * qd_).norm(); }

void ArmSim::step(double dt) {
  if (dt <= 0.0) return;
  if (stop_) {
    // The stopping model: unchanged through the reaction, then braking at the
    // model's deceleration (the tool's speed never above the model's profile).
    stop_elapsed_ += dt;
    const double allowed =
        stop_elapsed_ <= m_.stopping.reaction_s
            ? stop_from_speed_
            : std::max(0.0, stop_from_speed_ - m_.stopping.decel_m_s2 * (stop_elapsed_ - m_.stopping.reaction_s));
    const double v = tool_speed();
    if (allowed <= 0.0) qd_.setZero();
    else if (v > allowed) qd_ *= allowed / v;
  } else {
    Joints want = Joints::Zero();
    if (has_target_) {
      const Eigen::Vector3d to_go = world_from_base_.inverse().linear() * (target_ - tool_world());
      Eigen::Vector3d v = kGain * to_go;
      const double limit = std::min(target_speed_, m_.max_tool_speed) * scale_;
      if (v.norm() > limit) v *= limit / v.norm();
      const auto j = position_jacobian(m_, q_);
      const Eigen::Matrix3d jjt = j * j.transpose() + kDamping * kDamping * Eigen::Matrix3d::Identity();
      want = j.transpose() * jjt.ldlt().solve(v);
    }
    // Joint speed limits (scaled alike, so the tool keeps its direction), then acceleration.
    double over = 1.0;
    for (int i = 0; i < 6; ++i) over = std::max(over, std::abs(want(i)) / (m_.max_speed(i) * std::max(scale_, 1e-9)));
    if (scale_ <= 0.0) want.setZero();
    else want /= over;
    Joints delta = want - qd_;
    double accel_over = 1.0;
    for (int i = 0; i < 6; ++i) accel_over = std::max(accel_over, std::abs(delta(i)) / (m_.max_accel(i) * dt));
    qd_ += delta / accel_over;
  }
  q_ += qd_ * dt;
  for (int i = 0; i < 6; ++i) {
    if (q_(i) < m_.lower(i) || q_(i) > m_.upper(i)) {
      q_(i) = std::clamp(q_(i), m_.lower(i), m_.upper(i));
      qd_(i) = 0.0;
    }
  }
}

}  // namespace skelgraph::robot
