// The fusion component on a fake clock, driven through its topics: two
// calibrated sensors' raw skeletons and sync TICKs in, one fused skeleton per
// person out in the world frame; a sensor silent past its timeout makes the
// status DEGRADED and fusion goes on with the other; a sensor without a pose is
// named; the sensor back makes it OK again; a person both trackers lost is
// disposed. Time is the test's: only the clock it advances makes a sensor
// silent, whatever the machine's load.

#include <gtest/gtest.h>

#include <bitset>
#include <string>

#include "../support/test_support.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;
using skeleton::JointId;
using Eigen::Vector3d;

namespace {

// A standing person facing +z with the torso at `at`, in the frame of a
// sensor whose pose only translates by `sensor_at`.
skeleton::Skeleton seen_by(const std::string& sensor, const Vector3d& sensor_at, const Vector3d& at,
                           std::int64_t stamp_ns, std::uint64_t frame) {
  skeleton::Skeleton s;
  s.sensor_id = sensor;
  s.person_id = 7;
  s.frame_id = sensor;
  s.stamp_ns = stamp_ns;
  s.frame_number = frame;
  const std::pair<JointId, Vector3d> layout[] = {
      {JointId::Head, {0, 0.5, 0}},          {JointId::Neck, {0, 0.3, 0}},           {JointId::Torso, {0, 0, 0}},
      {JointId::LeftShoulder, {0.2, 0.3, 0}}, {JointId::LeftElbow, {0.25, 0, 0}},    {JointId::LeftHand, {0.3, -0.25, 0}},
      {JointId::RightShoulder, {-0.2, 0.3, 0}}, {JointId::RightElbow, {-0.25, 0, 0}}, {JointId::RightHand, {-0.3, -0.25, 0}},
      {JointId::LeftHip, {0.1, -0.2, 0}},    {JointId::LeftKnee, {0.1, -0.65, 0}},   {JointId::LeftFoot, {0.1, -1.1, 0}},
      {JointId::RightHip, {-0.1, -0.2, 0}},  {JointId::RightKnee, {-0.1, -0.65, 0}}, {JointId::RightFoot, {-0.1, -1.1, 0}}};
  for (const auto& [j, p] : layout) {
    s[j].position = at + p - sensor_at;
    s[j].confidence = skeleton::kTracked;
  }
  return s;
}

const Vector3d kS1(0, 1.2, 2), kS2(2, 1.2, 0);

// Every joint of a fused skeleton made from `sensors` inputs.
bool made_from(const skeleton::Skeleton& s, std::size_t sensors) {
  for (const auto& j : s.joints) {
    if (std::bitset<32>(j.sensor_mask).count() != sensors) return false;
  }
  return true;
}

struct Status {
  std::string name;
  msg::ComponentState state;
  std::string message;
};

}  // namespace

TEST(FusionComponent, FusesCalibratedSensorsOnTicksAndGoesOnWhenOneFallsSilent) {
  const auto registry = builtin_registry();
  auto clock = std::make_shared<FakeClock>(7'000'000'000'000);  // far from the wall clock: only this time counts
  auto config = test::test_config();
  config.clock = clock;
  Graph graph(registry, config, 100ms);
  graph.add("fusion", "fusion",
            registry.find("fusion")->info.params.resolve({{"method", "avg", "test"},
                                                          {"trigger", "ticks", "test"},
                                                          {"sensor_timeout_ms", "500", "test"},
                                                          {"person_timeout_ms", "1000", "test"}},
                                                         "fusion"));

  Context ctx("test_cell", config);
  Publisher<msg::SensorPose> poses(ctx, topics::kCalibration);
  Publisher<msg::Skeleton> raw(ctx, topics::kSkeletonRaw);
  Publisher<msg::SensorFrame> frames(ctx, topics::kSensorFrame);
  Publisher<msg::SyncCommand> sync(ctx, topics::kSync);
  test::Collector<skeleton::Skeleton> fused;
  test::Collector<std::uint32_t> departed;
  test::Collector<Status> status;
  Subscription<msg::Skeleton> fused_sub(
      ctx, topics::kSkeletonFused, [&](const msg::Skeleton& m, const SampleMeta&) { fused.add(skeleton::from_msg(m)); },
      [&](const msg::Skeleton& last, const SampleMeta&) { departed.add(last.person_id()); });
  Subscription<msg::ComponentStatus> status_sub(ctx, topics::kStatus, [&](const msg::ComponentStatus& m, const SampleMeta&) {
    status.add({m.component_name().to_string(), m.state(), m.message().to_string()});
  });
  ctx.executor().start();
  graph.start();
  for (const auto& [sensor, at] : {std::pair{"s1", kS1}, std::pair{"s2", kS2}}) {
    skeleton::SensorPose p;
    p.sensor_id = sensor;
    p.pose.translation() = at;
    p.method = "manual";
    ASSERT_TRUE(poses.publish(skeleton::to_msg(p)));
  }
  ASSERT_TRUE(poses.wait_for_matched(1, 10s));
  ASSERT_TRUE(poses.wait_for_acks(10s));
  ASSERT_TRUE(raw.wait_for_matched(1, 10s));
  ASSERT_TRUE(fused_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(test::wait_input_matched(graph.context("fusion"), topics::kSkeletonRaw.name));  // best effort
  ASSERT_TRUE(test::wait_input_matched(graph.context("fusion"), topics::kSensorFrame.name));

  std::uint64_t frame = 0, tick = 0;
  // One frame of each of `sensors` seen now, then a TICK, until the fused
  // skeletons meet `want` (raw skeletons are best effort: a round may be lost).
  const auto feed_until = [&](std::vector<std::pair<std::string, Vector3d>> sensors, const Vector3d& at,
                              const std::function<bool(const std::vector<skeleton::Skeleton>&)>& want) {
    for (int round = 0; round < 200; ++round) {
      ++frame;
      for (const auto& [sensor, sensor_at] : sensors) {
        raw.publish(skeleton::to_msg(seen_by(sensor, sensor_at, at, clock->now_ns(), frame)));
        msg::SensorFrame f;
        f.sensor_id(sensor);
        f.stamp_ns(clock->now_ns());
        f.frame_number(frame);
        f.people(1);
        frames.publish(f);
      }
      msg::SyncCommand t;
      t.kind(msg::SYNC_TICK);
      t.session_id(1);
      t.tick(++tick);
      t.master_stamp_ns(clock->now_ns());
      sync.publish(t);
      if (fused.wait(want, 50ms)) return true;
    }
    return false;
  };
  const auto state_of_fusion = [&](msg::ComponentState state, const std::string& words) {
    return status.wait(
        [&](const std::vector<Status>& v) {
          for (auto it = v.rbegin(); it != v.rend(); ++it) {
            if (it->name == "fusion") return it->state == state && it->message.find(words) != std::string::npos;
          }
          return false;
        },
        10s);
  };
  const auto last_at = [](const Vector3d& at, std::size_t sensors) {
    return [at, sensors](const std::vector<skeleton::Skeleton>& v) {
      return !v.empty() && made_from(v.back(), sensors) && (v.back()[JointId::Torso].position - at).norm() < 1e-3;
    };
  };

  // Both sensors: avg of two views of the same point is that point, in the world frame.
  const Vector3d here(0.5, 1.0, 1.0);
  ASSERT_TRUE(feed_until({{"s1", kS1}, {"s2", kS2}}, here, last_at(here, 2)));
  {
    const auto last = fused.items().back();
    EXPECT_EQ(last.frame_id, "world");
    EXPECT_EQ(last.sensor_id, "fused");
    EXPECT_NEAR((last[JointId::Head].position - (here + Vector3d(0, 0.5, 0))).norm(), 0.0, 1e-3);
  }
  ASSERT_TRUE(state_of_fusion(msg::STATE_OK, "fusing 2 sensor(s)"));

  // s2 falls silent: 600 ms later (past its 500 ms timeout) only s1 speaks; fusion goes on with s1 alone.
  clock->advance(600'000'000);
  const Vector3d there(0.8, 1.0, 1.2);
  ASSERT_TRUE(feed_until({{"s1", kS1}}, there, last_at(there, 1)));
  ASSERT_TRUE(state_of_fusion(msg::STATE_DEGRADED, "silent: s2"));

  // A third sensor with no pose is named, and its skeletons are not fused.
  ASSERT_TRUE(feed_until({{"s1", kS1}, {"s3", Vector3d::Zero()}}, there, last_at(there, 1)));
  ASSERT_TRUE(state_of_fusion(msg::STATE_DEGRADED, "no calibration for: s3"));

  // s2 back (and s3 gone quiet past its timeout too): both fused again, OK.
  clock->advance(600'000'000);
  ASSERT_TRUE(feed_until({{"s1", kS1}, {"s2", kS2}}, here, last_at(here, 2)));

  // Both trackers lose the person (they dispose the instance): the fused person is disposed.
  for (const auto* sensor : {"s1", "s2", "s3"}) {
    msg::Skeleton key;
    key.sensor_id(sensor);
    key.person_id(7);
    raw.dispose(key);
  }
  for (int round = 0; round < 100 && !departed.wait_count(1, 50ms); ++round) {
    msg::SyncCommand t;
    t.kind(msg::SYNC_TICK);
    t.tick(++tick);
    sync.publish(t);
  }
  ASSERT_TRUE(departed.wait_count(1, 1s));
  graph.stop();

  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  const auto& d = reports[0].details;
  EXPECT_EQ(d["method"], "avg");
  EXPECT_EQ(d["trigger"], "ticks");
  EXPECT_GT(d["tick_steps"].get<int>(), 0) << d;
  EXPECT_GE(d["dropouts"].get<int>(), 1) << d;
  EXPECT_GE(d["rejoins"].get<int>(), 1) << d;
  EXPECT_EQ(d["departed"], 1) << d;
  EXPECT_EQ(d["people"], 0) << d;
  EXPECT_GT(d["samples_without_pose"].get<int>(), 0) << d;
  EXPECT_EQ(d["sensors"].size(), 3u) << d;
}
