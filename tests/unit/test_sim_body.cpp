#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "skelgraph/sim/body.hpp"

using namespace skelgraph;
using skeleton::JointId;
using sim::BodyDimensions;
using sim::BodyPose;

namespace {
double dist(const skeleton::Skeleton& s, JointId a, JointId b) { return (s[a].position - s[b].position).norm(); }
constexpr double kPi = 3.14159265358979323846;
}  // namespace

TEST(SimBody, StandingPersonHasTheProportionsOfItsHeight) {
  const auto b = BodyDimensions::from_height(1.80);
  const auto s = sim::forward_kinematics(b, BodyPose{});
  EXPECT_NEAR(s[JointId::Head].position.y(), 0.936 * 1.80, 1e-9);
  EXPECT_NEAR(s[JointId::Neck].position.y(), 0.818 * 1.80, 1e-9);
  EXPECT_NEAR(s[JointId::LeftFoot].position.y(), 0.039 * 1.80, 1e-9);
  EXPECT_NEAR(s[JointId::LeftHand].position.y(), (0.818 - 0.186 - 0.195) * 1.80, 1e-9);  // arms hang
  EXPECT_NEAR(dist(s, JointId::LeftShoulder, JointId::RightShoulder), 0.259 * 1.80, 1e-9);
  // Heading 0 faces +z, so the person's left is +x.
  EXPECT_GT(s[JointId::LeftShoulder].position.x(), s[JointId::RightShoulder].position.x());
  for (const auto& j : s.joints) EXPECT_EQ(j.confidence, skeleton::kTracked);
  EXPECT_EQ(s.frame_id, "world");
  EXPECT_THROW(BodyDimensions::from_height(3.0), std::invalid_argument);
}

TEST(SimBody, FacingTheSensorPutsLeftAtSmallerX) {
  // A sensor at the origin looking along +z sees a person facing -z (heading pi):
  // the data sets' convention ShoulderLeft.x < ShoulderRight.x.
  BodyPose p;
  p.heading = kPi;
  p.floor_position = {0.0, 2.0};
  const auto s = sim::forward_kinematics(BodyDimensions::from_height(1.7), p);
  EXPECT_LT(s[JointId::LeftShoulder].position.x(), s[JointId::RightShoulder].position.x());
  EXPECT_NEAR(s[JointId::Torso].position.z(), 2.0, 1e-9);
}

TEST(SimBody, TPoseAndPointing) {
  const auto b = BodyDimensions::from_height(1.75);
  BodyPose t;
  t.left_arm = {kPi / 2, kPi / 2, 0.0};
  t.right_arm = {kPi / 2, kPi / 2, 0.0};
  const auto s = sim::forward_kinematics(b, t);
  EXPECT_NEAR(s[JointId::LeftHand].position.y(), s[JointId::LeftShoulder].position.y(), 1e-9);
  EXPECT_NEAR(dist(s, JointId::LeftHand, JointId::RightHand), b.shoulder_width + 2 * (b.upper_arm + b.forearm_hand),
              1e-9);
  // Pointing straight ahead with the right arm: the hand is in front of the shoulder at its height.
  BodyPose point;
  point.right_arm = {kPi / 2, 0.0, 0.0};
  const auto q = sim::forward_kinematics(b, point);
  const Eigen::Vector3d d = q[JointId::RightHand].position - q[JointId::RightShoulder].position;
  EXPECT_NEAR(d.z(), b.upper_arm + b.forearm_hand, 1e-9);
  EXPECT_NEAR(d.y(), 0.0, 1e-9);
  // A bent elbow on a hanging arm brings the hand forwards and up.
  BodyPose bent;
  bent.left_arm.elbow_flex = kPi / 2;
  const auto r = sim::forward_kinematics(b, bent);
  EXPECT_NEAR(r[JointId::LeftHand].position.y(), r[JointId::LeftElbow].position.y(), 1e-9);
  EXPECT_NEAR(r[JointId::LeftHand].position.z() - r[JointId::LeftElbow].position.z(), b.forearm_hand, 1e-9);
}

TEST(SimBody, SittingDropsThePelvisAndBendsTheKnees) {
  const auto b = BodyDimensions::from_height(1.75);
  BodyPose sit;
  sit.pelvis_drop = b.hip_height - 0.45;  // a 45 cm chair
  sit.left_leg = sit.right_leg = {kPi / 2, kPi / 2};
  const auto s = sim::forward_kinematics(b, sit);
  EXPECT_NEAR(s[JointId::LeftHip].position.y(), 0.45, 1e-9);
  EXPECT_NEAR(s[JointId::LeftKnee].position.y(), 0.45, 1e-9);  // thigh horizontal
  EXPECT_NEAR(s[JointId::LeftKnee].position.z(), b.thigh, 1e-9);
  EXPECT_NEAR(s[JointId::LeftFoot].position.y(), 0.45 - b.shank, 1e-9);  // shank vertical
}

TEST(SimBody, BoneLengthsNeverChangeWhateverThePose) {
  const auto b = BodyDimensions::from_height(1.65);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi), small(-0.6, 0.6), pos(-3.0, 3.0);
  const std::pair<JointId, JointId> bones[] = {
      {JointId::LeftShoulder, JointId::LeftElbow}, {JointId::LeftElbow, JointId::LeftHand},
      {JointId::RightShoulder, JointId::RightElbow}, {JointId::RightElbow, JointId::RightHand},
      {JointId::LeftHip, JointId::LeftKnee},       {JointId::LeftKnee, JointId::LeftFoot},
      {JointId::Neck, JointId::Head},              {JointId::LeftShoulder, JointId::RightShoulder}};
  const double lengths[] = {b.upper_arm, b.forearm_hand, b.upper_arm, b.forearm_hand,
                            b.thigh,     b.shank,        b.neck_to_head, b.shoulder_width};
  for (int i = 0; i < 200; ++i) {
    BodyPose p;
    p.floor_position = {pos(rng), pos(rng)};
    p.heading = angle(rng);
    p.trunk_pitch = small(rng);
    p.left_arm = {std::abs(angle(rng)), angle(rng), std::abs(small(rng)) * 3};
    p.right_arm = {std::abs(angle(rng)), angle(rng), std::abs(small(rng)) * 3};
    p.left_leg = {small(rng), std::abs(small(rng))};
    const auto s = sim::forward_kinematics(b, p);
    for (std::size_t k = 0; k < std::size(bones); ++k) {
      EXPECT_NEAR(dist(s, bones[k].first, bones[k].second), lengths[k], 1e-9) << "pose " << i << " bone " << k;
    }
    for (const auto& j : s.joints) EXPECT_NEAR(j.orientation.norm(), 1.0, 1e-9);
    // Bone-aligned orientation: the hand's local +y is the forearm direction.
    const Eigen::Vector3d fore =
        (s[JointId::LeftHand].position - s[JointId::LeftElbow].position).normalized();
    EXPECT_NEAR((s[JointId::LeftHand].orientation * Eigen::Vector3d::UnitY()).dot(fore), 1.0, 1e-9) << "pose " << i;
  }
}
