// The separation component's fail-safe paths on a fake clock (issue 32),
// driven through its topics: with a worker far from the arm, two live sensors
// and a fresh robot state it lets the robot run; then each of stale people
// data, a stale robot state, a lost sensor (fewer live than min_sensors) and a
// person fusion cannot place is a protective stop, said with its reason on
// skelgraph/safety and commanded on skelgraph/robot/command, and fresh data
// lets it run again. Time is the test's: only the clock it advances makes data
// old, whatever the machine's load.

#include <gtest/gtest.h>

#include <string>

#include "../support/test_support.hpp"
#include "skelgraph/robot/arm.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;
using skeleton::JointId;

namespace {

// A standing worker with the torso at (x, 1.0, z) in the world, every joint tracked (or none: unplaced).
skeleton::Skeleton worker(double x, double z, std::int64_t stamp_ns, bool placed = true) {
  skeleton::Skeleton s;
  s.person_id = 3;
  s.frame_id = "world";
  s.stamp_ns = stamp_ns;
  s.capture_newest_ns = stamp_ns;
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    s.joints[j].position = Eigen::Vector3d(x, 1.0, z);
    s.joints[j].confidence = placed ? skeleton::kTracked : skeleton::kLost;
  }
  s[JointId::Head].position.y() = 1.6;
  s[JointId::LeftFoot].position.y() = s[JointId::RightFoot].position.y() = 0.05;
  return s;
}

struct Verdict {
  msg::SafetyStateKind state;
  std::string reason;
};

}  // namespace

TEST(SeparationComponent, EachFailSafeStopsTheRobotWithItsReasonAndFreshDataLetsItRun) {
  const auto registry = builtin_registry();
  auto clock = std::make_shared<FakeClock>(9'000'000'000'000);  // far from the wall clock: only this time counts
  auto config = test::test_config();
  config.clock = clock;
  Graph graph(registry, config, 100ms);
  graph.add("separation", "separation",
            registry.find("separation")->info.params.resolve({{"min_sensors", "2", "test"},
                                                              {"release_ms", "0", "test"},
                                                              {"sensor_timeout_ms", "500", "test"},
                                                              {"person_timeout_ms", "2000", "test"},
                                                              {"max_people_age_ms", "250", "test"},
                                                              {"max_robot_age_ms", "100", "test"}},
                                                             "separation"));
  Context ctx("test_cell", config);
  Publisher<msg::Skeleton> fused(ctx, topics::kSkeletonFused);
  Publisher<msg::RobotState> robot(ctx, topics::kRobotState);
  Publisher<msg::SensorFrame> frames(ctx, topics::kSensorFrame);
  test::Collector<Verdict> verdicts;
  test::Collector<msg::RobotCommandKind> commands;
  Subscription<msg::SafetyStatus> safety_sub(ctx, topics::kSafety, [&](const msg::SafetyStatus& s, const SampleMeta&) {
    verdicts.add({s.state(), s.reason().to_string()});
  });
  Subscription<msg::RobotCommand> command_sub(ctx, topics::kRobotCommand,
                                              [&](const msg::RobotCommand& c, const SampleMeta&) { commands.add(c.kind()); });
  ctx.executor().start();
  graph.start();
  ASSERT_TRUE(fused.wait_for_matched(1, 10s));
  ASSERT_TRUE(robot.wait_for_matched(1, 10s));
  ASSERT_TRUE(frames.wait_for_matched(1, 10s));
  ASSERT_TRUE(safety_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(command_sub.wait_for_matched(1, 10s));
  const auto& sep = graph.context("separation");
  for (const auto& topic : {topics::kSkeletonFused.name, topics::kRobotState.name, topics::kSensorFrame.name})
    ASSERT_TRUE(test::wait_input_matched(sep, topic)) << topic;  // best effort: the first samples must not be dropped

  const robot::ArmSim arm(robot::ArmModel::ur5e(), robot::base_pose(0.0, 0.0, 1.9, 180.0),
                          (robot::Joints() << 0.0, -M_PI / 2, M_PI / 2, -M_PI / 2, -M_PI / 2, 0.0).finished());
  // Everything the monitor reads, stamped now (by the fake clock), and taken by it.
  std::uint64_t sent_frames = 0, sent_people = 0, sent_states = 0;
  const auto send = [&](bool person, bool placed, bool state, std::initializer_list<const char*> sensors) {
    const auto now = clock->now_ns();
    for (const char* s : sensors) {
      msg::SensorFrame f;
      f.sensor_id(s);
      f.stamp_ns(now);
      ASSERT_TRUE(frames.publish(f));
      ++sent_frames;
    }
    if (person) {
      ASSERT_TRUE(fused.publish(skeleton::to_msg(worker(0.0, -3.0, now, placed))));  // 3 m beyond the base, 4.9 m from it
      ++sent_people;
    }
    if (state) {
      ASSERT_TRUE(robot.publish(robot::state_msg("robot1", arm, now)));
      ++sent_states;
    }
    ASSERT_TRUE(test::wait_input_count(sep, topics::kSensorFrame.name, sent_frames));
    ASSERT_TRUE(test::wait_input_count(sep, topics::kSkeletonFused.name, sent_people));
    ASSERT_TRUE(test::wait_input_count(sep, topics::kRobotState.name, sent_states));
  };
  // Until the monitor's latest verdict (it decides on its own timer) is `state` with `reason` in it.
  const auto verdict_is = [&](msg::SafetyStateKind state, const std::string& reason) {
    return verdicts.wait(
        [&](const std::vector<Verdict>& v) {
          return !v.empty() && v.back().state == state && v.back().reason.find(reason) != std::string::npos;
        },
        10s);
  };
  const auto last_reason = [&] {
    const auto v = verdicts.items();
    return v.empty() ? std::string("(no verdict)") : v.back().reason;
  };
  const auto run_again = [&] {
    send(true, true, true, {"s1", "s2"});
    ASSERT_TRUE(verdict_is(msg::SAFETY_RUN, "")) << last_reason();
  };
  // Commands of a kind since the first run (before any data the monitor stops the robot: "no people data yet").
  std::size_t first = 0;
  const auto count = [&](const std::vector<msg::RobotCommandKind>& all, msg::RobotCommandKind kind) {
    std::size_t n = 0;
    for (std::size_t i = first; i < all.size(); ++i) n += all[i] == kind;
    return n;
  };
  const auto commanded = [&](msg::RobotCommandKind kind) { return count(commands.items(), kind); };

  // Fresh and far: run (the robot resumed).
  run_again();
  ASSERT_TRUE(commands.wait([](const auto& v) { return !v.empty() && v.back() == msg::ROBOT_RESUME; }, 10s));
  first = commands.items().size();
  // Stale people data: 300 ms with nothing new (limit 250).
  clock->advance(300'000'000);
  send(false, false, true, {});
  ASSERT_TRUE(verdict_is(msg::SAFETY_PROTECTIVE_STOP, "people data 300 ms old (limit 250 ms)")) << last_reason();
  run_again();
  // A stale robot state: people and sensors fresh, the robot's state 150 ms old (limit 100).
  clock->advance(150'000'000);
  send(true, true, false, {"s1", "s2"});
  ASSERT_TRUE(verdict_is(msg::SAFETY_PROTECTIVE_STOP, "robot state 150 ms old (limit 100 ms)")) << last_reason();
  run_again();
  // A lost sensor: s2 silent for 600 ms (timeout 500), one live of the two needed.
  clock->advance(600'000'000);
  send(true, true, true, {"s1"});
  ASSERT_TRUE(verdict_is(msg::SAFETY_PROTECTIVE_STOP, "is lost and no other covers it")) << last_reason();
  run_again();
  // A person fusion cannot place (every joint unplaced), however far the others are.
  send(true, false, true, {"s1", "s2"});
  ASSERT_TRUE(verdict_is(msg::SAFETY_PROTECTIVE_STOP, "a person fusion cannot place")) << last_reason();
  run_again();
  // Each stop was commanded to the robot, and each run after it resumed it.
  ASSERT_TRUE(commands.wait([&](const auto& all) { return count(all, msg::ROBOT_RESUME) >= 4; }, 10s))
      << commanded(msg::ROBOT_RESUME);
  graph.stop();
  EXPECT_EQ(commanded(msg::ROBOT_PROTECTIVE_STOP), 4u);
  EXPECT_EQ(commanded(msg::ROBOT_RESUME), 4u);
  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  // The four, and the one before any data if the monitor decided before the first samples came (its
  // command may have gone out before this test's reader matched).
  const int stops = reports[0].details["protective_stops"];
  EXPECT_TRUE(stops == 4 || stops == 5) << reports[0].details;
  EXPECT_EQ(reports[0].details["failed_writes"], 0);
}
