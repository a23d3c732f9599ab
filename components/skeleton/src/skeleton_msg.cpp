#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::skeleton {

static_assert(kJointCount == msg::JOINT_COUNT, "canonical joints and the IDL disagree");
static_assert(static_cast<int>(JointId::RightFoot) == msg::JOINT_RIGHT_FOOT, "joint order differs from the IDL");
static_assert(static_cast<int>(JointId::LeftHand) == msg::JOINT_LEFT_HAND, "joint order differs from the IDL");

namespace {
void set(msg::Vec3& m, const Eigen::Vector3d& v) {
  m.x(v.x());
  m.y(v.y());
  m.z(v.z());
}
void set(msg::Quat& m, const Eigen::Quaterniond& q) {
  m.w(q.w());
  m.x(q.x());
  m.y(q.y());
  m.z(q.z());
}
}  // namespace

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
    set(o.position(), j.position);
    set(o.orientation(), j.orientation);
    o.confidence(j.confidence);
    o.sensor_mask(j.sensor_mask);
    auto& c = m.covariance()[i];
    c.xx(j.covariance[0]);
    c.xy(j.covariance[1]);
    c.xz(j.covariance[2]);
    c.yy(j.covariance[3]);
    c.yz(j.covariance[4]);
    c.zz(j.covariance[5]);
  }
  m.capture_oldest_ns(s.capture_oldest_ns != 0 ? s.capture_oldest_ns : s.stamp_ns);
  m.capture_newest_ns(s.capture_newest_ns != 0 ? s.capture_newest_ns : s.stamp_ns);
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
    const auto& c = m.covariance()[i];
    j.covariance = {c.xx(), c.xy(), c.xz(), c.yy(), c.yz(), c.zz()};
  }
  s.capture_oldest_ns = m.capture_oldest_ns();
  s.capture_newest_ns = m.capture_newest_ns();
  return s;
}

msg::SensorPose to_msg(const SensorPose& p) {
  msg::SensorPose m;
  m.sensor_id(p.sensor_id.substr(0, 64));
  m.frame_id(p.frame_id.substr(0, 64));
  set(m.translation(), p.pose.translation());
  set(m.rotation(), Eigen::Quaterniond(p.pose.rotation()));
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
