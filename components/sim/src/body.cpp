#include "skelgraph/sim/body.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace skelgraph::sim {

using Eigen::AngleAxisd;
using Eigen::Quaterniond;
using Eigen::Vector3d;
using skeleton::JointId;

BodyDimensions BodyDimensions::from_height(double h) {
  if (!(h >= 0.5 && h <= 2.5)) throw std::invalid_argument("body height must be 0.5-2.5 m, got " + std::to_string(h));
  BodyDimensions d;
  d.height = h;
  for (double* v : {&d.hip_height, &d.hip_width, &d.trunk, &d.neck_to_head, &d.shoulder_width, &d.upper_arm,
                    &d.forearm_hand, &d.thigh, &d.shank, &d.ankle_height}) {
    *v *= h;
  }
  return d;
}

namespace {

// Orientation whose local +y points along `dir`, starting from the trunk frame.
Quaterniond along(const Quaterniond& trunk, const Vector3d& trunk_up, const Vector3d& dir) {
  return (Quaterniond::FromTwoVectors(trunk_up, dir) * trunk).normalized();
}

struct Arm {
  Vector3d elbow, hand, upper_dir, fore_dir;
};

Arm arm(const BodyDimensions& b, const ArmPose& a, const Vector3d& shoulder, const Vector3d& up, const Vector3d& fwd,
        const Vector3d& out, double side_sign) {
  Arm r;
  r.upper_dir = (std::cos(a.elevation) * -up +
                 std::sin(a.elevation) * (std::cos(a.azimuth) * fwd + std::sin(a.azimuth) * out))
                    .normalized();
  r.elbow = shoulder + b.upper_arm * r.upper_dir;
  // The elbow bends the forearm towards the front, or upwards when the upper
  // arm itself points forward.
  const Vector3d target = std::abs(r.upper_dir.dot(fwd)) < 0.9 ? fwd : up;
  Vector3d axis = r.upper_dir.cross(target);
  if (axis.norm() < 1e-9) axis = out;
  // Positive twist turns the bend towards the midline on either side.
  axis = AngleAxisd(side_sign * a.bend_twist, r.upper_dir) * axis;
  r.fore_dir = (AngleAxisd(a.elbow_flex, axis.normalized()) * r.upper_dir).normalized();
  r.hand = r.elbow + b.forearm_hand * r.fore_dir;
  return r;
}

}  // namespace

skeleton::Skeleton forward_kinematics(const BodyDimensions& b, const BodyPose& p) {
  const Vector3d world_up = Vector3d::UnitY();
  const Vector3d fwd(std::sin(p.heading), 0.0, std::cos(p.heading));
  const Vector3d left = world_up.cross(fwd);
  // The trunk bends forward about the left axis.
  const AngleAxisd bend(p.trunk_pitch, left);
  const Vector3d up_t = bend * world_up;
  const Vector3d fwd_t = bend * fwd;
  const Quaterniond body_q = Quaterniond(AngleAxisd(p.heading, world_up));
  const Quaterniond trunk_q = (Quaterniond(bend) * body_q).normalized();

  const Vector3d pelvis(p.floor_position.x(), b.hip_height - p.pelvis_drop, p.floor_position.y());
  const Vector3d neck = pelvis + b.trunk * up_t;
  skeleton::Skeleton s;
  s.frame_id = "world";
  auto set = [&s](JointId id, const Vector3d& pos, const Quaterniond& q) {
    s[id].position = pos;
    s[id].orientation = q;
    s[id].confidence = skeleton::kTracked;
  };
  set(JointId::Neck, neck, trunk_q);
  set(JointId::Torso, 0.5 * (pelvis + neck), trunk_q);
  set(JointId::Head, neck + b.neck_to_head * up_t, trunk_q);

  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? 1.0 : -1.0;  // left, right
    const Vector3d out = sign * left;
    const auto& ap = side == 0 ? p.left_arm : p.right_arm;
    const auto& lp = side == 0 ? p.left_leg : p.right_leg;
    const Vector3d shoulder = neck + 0.5 * b.shoulder_width * out;
    const Arm a = arm(b, ap, shoulder, up_t, fwd_t, out, sign);
    // Legs hang from the pelvis in the body's (unbent) frame.
    const Vector3d hip = pelvis + 0.5 * b.hip_width * out;
    const Vector3d thigh_dir = AngleAxisd(-lp.hip_flex, left) * -world_up;
    const Vector3d knee = hip + b.thigh * thigh_dir;
    const Vector3d shank_dir = AngleAxisd(-lp.hip_flex + lp.knee_flex, left) * -world_up;
    const Vector3d foot = knee + b.shank * shank_dir;
    const bool l = side == 0;
    set(l ? JointId::LeftShoulder : JointId::RightShoulder, shoulder, trunk_q);
    set(l ? JointId::LeftElbow : JointId::RightElbow, a.elbow, along(trunk_q, up_t, a.upper_dir));
    set(l ? JointId::LeftHand : JointId::RightHand, a.hand, along(trunk_q, up_t, a.fore_dir));
    set(l ? JointId::LeftHip : JointId::RightHip, hip, body_q);
    set(l ? JointId::LeftKnee : JointId::RightKnee, knee, along(body_q, world_up, thigh_dir));
    set(l ? JointId::LeftFoot : JointId::RightFoot, foot, along(body_q, world_up, shank_dir));
  }
  return s;
}

}  // namespace skelgraph::sim
