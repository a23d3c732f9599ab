#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::skeleton {

static_assert(kJointCount == msg::JOINT_COUNT, "canonical joints and the IDL disagree");
static_assert(static_cast<int>(JointId::RightFoot) == msg::JOINT_RIGHT_FOOT, "joint order differs from the IDL");
static_assert(static_cast<int>(JointId::LeftHand) == msg::JOINT_LEFT_HAND, "joint order differs from the IDL");

msg::Skeleton to_msg(const Skeleton& s) {
  msg::Skeleton m;
  m.sensor_id(s.sensor_id.substr(0, 64));
  m.person_id(s.person_id);
  m.frame_id(s.frame_id.substr(0, 64));
  m.stamp_ns(s.stamp_ns);
  m.frame_number(s.frame_number);
  for (std::size_t i = 0; i < kJointCount; ++i) {
    const auto& j = s.joints[i];
    auto& o = m.joints()[i];
    o.position().x(j.position.x());
    o.position().y(j.position.y());
    o.position().z(j.position.z());
    o.orientation().w(j.orientation.w());
    o.orientation().x(j.orientation.x());
    o.orientation().y(j.orientation.y());
    o.orientation().z(j.orientation.z());
    o.confidence(j.confidence);
    o.sensor_mask(j.sensor_mask);
  }
  return m;
}

Skeleton from_msg(const msg::Skeleton& m) {
  Skeleton s;
  s.sensor_id = m.sensor_id().to_string();
  s.person_id = m.person_id();
  s.frame_id = m.frame_id().to_string();
  s.stamp_ns = m.stamp_ns();
  s.frame_number = m.frame_number();
  for (std::size_t i = 0; i < kJointCount; ++i) {
    const auto& o = m.joints()[i];
    auto& j = s.joints[i];
    j.position = {o.position().x(), o.position().y(), o.position().z()};
    j.orientation = Eigen::Quaterniond(o.orientation().w(), o.orientation().x(), o.orientation().y(), o.orientation().z());
    j.confidence = o.confidence();
    j.sensor_mask = o.sensor_mask();
  }
  return s;
}

msg::SensorPose to_msg(const SensorPose& p) {
  msg::SensorPose m;
  m.sensor_id(p.sensor_id.substr(0, 64));
  m.frame_id(p.frame_id.substr(0, 64));
  const Eigen::Vector3d t = p.pose.translation();
  const Eigen::Quaterniond q(p.pose.rotation());
  m.translation().x(t.x());
  m.translation().y(t.y());
  m.translation().z(t.z());
  m.rotation().w(q.w());
  m.rotation().x(q.x());
  m.rotation().y(q.y());
  m.rotation().z(q.z());
  m.stamp_ns(p.stamp_ns);
  m.method(p.method.substr(0, 64));
  m.rms_residual_m(p.rms_residual_m);
  m.max_residual_m(p.max_residual_m);
  return m;
}

SensorPose from_msg(const msg::SensorPose& m) {
  SensorPose p;
  p.sensor_id = m.sensor_id().to_string();
  p.frame_id = m.frame_id().to_string();
  p.pose = Eigen::Isometry3d::Identity();
  p.pose.linear() =
      Eigen::Quaterniond(m.rotation().w(), m.rotation().x(), m.rotation().y(), m.rotation().z()).normalized().toRotationMatrix();
  p.pose.translation() = Eigen::Vector3d(m.translation().x(), m.translation().y(), m.translation().z());
  p.stamp_ns = m.stamp_ns();
  p.method = m.method().to_string();
  p.rms_residual_m = m.rms_residual_m();
  p.max_residual_m = m.max_residual_m();
  return p;
}

}  // namespace skelgraph::skeleton
