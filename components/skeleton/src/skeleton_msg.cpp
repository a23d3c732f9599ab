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

}  // namespace skelgraph::skeleton
