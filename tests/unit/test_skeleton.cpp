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

// --- A source's stamps onto the receive clock ---

#include <random>

#include "skelgraph/skeleton/stamp_map.hpp"

// A source whose clock runs twice as fast and 40 s ahead, delivering its
// 30 Hz frames in bursts (the publisher wakes every 5-300 ms and sends all
// it has): mapped stamps keep the frames' spacing on the receive clock.
TEST(StampMap, KeepsTheSpacingOfFramesDeliveredInBursts) {
  skeleton::StampMap m;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> wake(0.005, 0.3);
  const std::int64_t epoch = 1'700'000'000'000'000'000;
  double next_wake = 0;
  std::vector<std::pair<double, std::int64_t>> frames;  // (capture time on the receive clock, receive ns)
  for (int f = 0; f < 900; ++f) {
    const double t = f / 30.0;
    while (next_wake < t) next_wake += wake(rng);
    const auto receive = epoch + static_cast<std::int64_t>(std::llround(next_wake * 1e9));
    const auto stamp = epoch + 40'000'000'000 + static_cast<std::int64_t>(std::llround(2 * t * 1e9));
    m.add(stamp, receive);
    frames.emplace_back(t, stamp);
  }
  EXPECT_NEAR(m.rate(), 0.5, 0.005);
  // The last 20 s (the window): each frame 33.3 ms after the one before, within 1 ms; by receive
  // time alone some come 0 ms and some 300 ms apart.
  double worst_ms = 0;
  for (std::size_t i = frames.size() - 590; i < frames.size(); ++i) {
    const double gap_ms = static_cast<double>(m.to_receive(frames[i].second) - m.to_receive(frames[i - 1].second)) * 1e-6;
    worst_ms = std::max(worst_ms, std::abs(gap_ms - 1000.0 / 30));
  }
  EXPECT_LT(worst_ms, 1.0);
  // On the receive clock, no earlier than the capture and within the mean burst delay (about 75 ms).
  const double lag_ms = static_cast<double>(m.to_receive(frames.back().second) - epoch) * 1e-6 - frames.back().first * 1e3;
  EXPECT_GT(lag_ms, 20.0);
  EXPECT_LT(lag_ms, 150.0);
  EXPECT_EQ(m.restarts(), 0u);
}

// A source that restarts (its stamps jump back) is fitted again from its new frames.
TEST(StampMap, AStampThatJumpsStartsTheFitAgain) {
  skeleton::StampMap m;
  EXPECT_EQ(m.to_receive(1234), 1234);  // nothing known: the stamp itself
  for (int f = 0; f < 100; ++f) m.add(5'000'000'000 + f * 33'000'000LL, 1'000'000'000 + f * 33'000'000LL);
  EXPECT_EQ(m.to_receive(5'000'000'000), 1'000'000'000);
  for (int f = 0; f < 10; ++f) m.add(f * 33'000'000LL, 4'400'000'000 + f * 33'000'000LL);
  EXPECT_EQ(m.restarts(), 1u);
  EXPECT_EQ(m.size(), 10u);
  EXPECT_EQ(m.to_receive(0), 4'400'000'000);
}
