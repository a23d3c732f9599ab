#include <gtest/gtest.h>

#include "skelgraph/skeleton/skeleton.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using skeleton::JointId;

TEST(Skeleton, JointNamesRoundTripAndMatchTheWireNames) {
  for (std::size_t i = 0; i < skeleton::kJointCount; ++i) {
    const auto id = skeleton::joint_at(i);
    EXPECT_EQ(skeleton::joint_from_name(skeleton::joint_name(id)), id);
    EXPECT_STREQ(skeleton::joint_name(id), msg::joint_name(static_cast<msg::JointId>(i)));
  }
  EXPECT_FALSE(skeleton::joint_from_name("left_wrist").has_value());
}

TEST(Skeleton, MessageConversionKeepsEverything) {
  skeleton::Skeleton s;
  s.sensor_id = "kinect_a";
  s.person_id = 4;
  s.frame_id = "kinect_a";
  s.stamp_ns = -17;
  s.frame_number = 99;
  for (std::size_t i = 0; i < skeleton::kJointCount; ++i) {
    s.joints[i].position = {0.5 * i, -1.0 * i, 2.0};
    s.joints[i].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ()));
    s.joints[i].confidence = i % 2 ? 0.5f : 1.0f;
    s.joints[i].sensor_mask = 1u << i;
  }
  const auto m = skeleton::to_msg(s);
  EXPECT_EQ(m.joints()[msg::JOINT_RIGHT_HAND].position().x(), s[JointId::RightHand].position.x());
  const auto back = skeleton::from_msg(m);
  EXPECT_EQ(back.sensor_id, s.sensor_id);
  EXPECT_EQ(back.person_id, s.person_id);
  EXPECT_EQ(back.frame_id, s.frame_id);
  EXPECT_EQ(back.stamp_ns, s.stamp_ns);
  EXPECT_EQ(back.frame_number, s.frame_number);
  for (std::size_t i = 0; i < skeleton::kJointCount; ++i) {
    EXPECT_EQ(back.joints[i].position, s.joints[i].position);
    EXPECT_EQ(back.joints[i].orientation.coeffs(), s.joints[i].orientation.coeffs());
    EXPECT_EQ(back.joints[i].confidence, s.joints[i].confidence);
    EXPECT_EQ(back.joints[i].sensor_mask, s.joints[i].sensor_mask);
  }
}
