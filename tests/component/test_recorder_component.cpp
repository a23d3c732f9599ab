// The recorder component on a fake clock, driven through its topics: a sync
// START opens <label>_<session>_<host>.mcap with the sensor poses published
// before it (transient-local), every sample that comes during the session is
// in it with the recorder's clock as log time, every TICK is answered on
// skelgraph/sync_ack with this host's clocks, and STOP closes a valid file.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "../support/test_support.hpp"
#include "skelgraph/recording/info.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

namespace {
msg::SyncCommand sync_command(msg::SyncKind kind, std::uint64_t tick, std::int64_t stamp_ns) {
  msg::SyncCommand c;
  c.kind(kind);
  c.session_id(3);
  c.label("cell");
  c.tick(tick);
  c.master_stamp_ns(stamp_ns);
  return c;
}
}  // namespace

TEST(RecorderComponent, RecordsASyncSessionAndAcknowledgesEveryTick) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "recorder_component";
  std::filesystem::remove_all(dir);
  const std::int64_t t0 = 11'000'000'000'000;
  auto clock = std::make_shared<FakeClock>(t0);
  auto config = test::test_config();
  config.clock = clock;
  const auto registry = builtin_registry();
  Graph graph(registry, config, 100ms);
  graph.add("recorder", "recorder",
            registry.find("recorder")->info.params.resolve(
                {{"directory", dir.string(), "test"}, {"host", "h1", "test"}, {"stop_linger_ms", "0", "test"}},
                "recorder"));

  Context ctx("test_cell", config);
  Publisher<msg::SensorPose> poses(ctx, topics::kCalibration);
  Publisher<msg::SyncCommand> sync(ctx, topics::kSync);
  Publisher<msg::Skeleton> raw(ctx, topics::kSkeletonRaw);
  test::Collector<msg::SyncAck> acks;
  Subscription<msg::SyncAck> ack_sub(ctx, topics::kSyncAck, [&](const msg::SyncAck& a, const SampleMeta&) { acks.add(a); });
  test::Collector<std::string> status;
  Subscription<msg::ComponentStatus> status_sub(ctx, topics::kStatus, [&](const msg::ComponentStatus& m, const SampleMeta&) {
    if (m.component_name() == "recorder") status.add(m.message().to_string());
  });
  ctx.executor().start();
  graph.start();
  ASSERT_TRUE(poses.wait_for_matched(1, 10s));
  ASSERT_TRUE(sync.wait_for_matched(1, 10s));
  ASSERT_TRUE(raw.wait_for_matched(1, 10s));
  ASSERT_TRUE(ack_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(test::wait_input_matched(graph.context("recorder"), topics::kSkeletonRaw.name));  // best effort

  // Before the session: a sensor pose (kept for late joiners, so it goes into the file).
  skeleton::SensorPose pose;
  pose.sensor_id = "sensor1";
  pose.pose.translation() = Eigen::Vector3d(0, 1.2, 2);
  ASSERT_TRUE(poses.publish(skeleton::to_msg(pose)));
  ASSERT_TRUE(poses.wait_for_acks(10s));
  const auto& rec_ctx = graph.context("recorder");
  ASSERT_TRUE(test::wait_input_count(rec_ctx, topics::kCalibration.name, 1));

  // START, then TICK 1: its ack says the recorder has opened the session.
  ASSERT_TRUE(sync.publish(sync_command(msg::SYNC_START, 0, clock->now_ns())));
  clock->advance(33'000'000);
  ASSERT_TRUE(sync.publish(sync_command(msg::SYNC_TICK, 1, clock->now_ns())));
  ASSERT_TRUE(acks.wait_count(1, 10s));

  // 40 raw skeletons (each taken before the next: best effort), and ticks 2..5.
  for (int i = 0; i < 40; ++i) {
    skeleton::Skeleton s;
    s.sensor_id = "sensor1";
    s.person_id = 1;
    s.frame_id = "sensor1";
    s.stamp_ns = clock->now_ns();
    s.frame_number = static_cast<std::uint64_t>(i);
    s[skeleton::JointId::Torso].position = {0.01 * i, 1.0, 2.0};
    s[skeleton::JointId::Torso].confidence = skeleton::kTracked;
    ASSERT_TRUE(raw.publish(skeleton::to_msg(s)));
    ASSERT_TRUE(test::wait_input_count(rec_ctx, topics::kSkeletonRaw.name, static_cast<std::uint64_t>(i + 1)))
        << "skeleton " << i;
    clock->advance(10'000'000);
  }
  for (std::uint64_t t = 2; t <= 5; ++t) {
    ASSERT_TRUE(sync.publish(sync_command(msg::SYNC_TICK, t, clock->now_ns())));
    clock->advance(33'000'000);
  }
  ASSERT_TRUE(acks.wait_count(5, 10s));
  // The recorder records its own acks too: all five in before STOP (linger 0 closes at once).
  ASSERT_TRUE(test::wait_input_count(rec_ctx, topics::kSyncAck.name, 5));
  const auto path = dir / "cell_3_h1.mcap";
  ASSERT_TRUE(sync.publish(sync_command(msg::SYNC_STOP, 5, clock->now_ns())));
  // Closed at STOP (linger 0), before any shutdown: the status says so.
  ASSERT_TRUE(status.wait([&](const auto& v) { return !v.empty() && v.back() == "wrote " + path.string(); }, 10s))
      << (status.items().empty() ? "" : status.items().back());
  const auto acks_got = acks.items();
  ASSERT_EQ(acks_got.size(), 5u);
  for (std::size_t i = 0; i < acks_got.size(); ++i) {
    EXPECT_EQ(acks_got[i].tick(), i + 1);
    EXPECT_EQ(acks_got[i].host(), "h1");
    EXPECT_EQ(acks_got[i].session_id(), 3u);
    EXPECT_EQ(acks_got[i].component_name(), "recorder");
    // The recorder's own clock (the fake one) at receipt.
    EXPECT_GE(acks_got[i].receive_stamp_ns(), t0);
    EXPECT_LE(acks_got[i].receive_stamp_ns(), clock->now_ns());
  }
  graph.stop();
  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  ASSERT_TRUE(std::filesystem::exists(path)) << reports[0].details;

  const auto info = recording::recording_info(path.string());
  EXPECT_TRUE(info["valid"].get<bool>()) << info["problem"];
  EXPECT_EQ(info["skeletons_per_sensor"]["skelgraph/skeleton/raw sensor1"], 40) << info["skeletons_per_sensor"];
  EXPECT_EQ(info["ticks"], 5) << info;
  EXPECT_EQ(info["ticks_acked_by_host"]["h1"], 5) << info["ticks_acked_by_host"];
  ASSERT_EQ(info["sessions"].size(), 1u) << info["sessions"];
  // Log times are the recorder's clock: inside what the fake clock showed.
  EXPECT_GE(info["start_ns"].get<std::int64_t>(), t0);
  EXPECT_LE(info["end_ns"].get<std::int64_t>(), clock->now_ns());
  std::int64_t poses_in_file = -1;
  for (const auto& t : info["topics"]) {
    if (t["topic"] == topics::kCalibration.name) poses_in_file = t["count"].get<std::int64_t>();
  }
  EXPECT_EQ(poses_in_file, 1) << info["topics"];
}
