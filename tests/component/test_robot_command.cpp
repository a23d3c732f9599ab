// The robot component's command path on a fake clock (issue 39): a command
// from a source it knows, stamped by the clock it runs on, is taken; one from
// an unknown source, or stamped too long ago or ahead, is refused, counted and
// said on its status. Driven through DDS on loopback; the time is the test's.

#include <gtest/gtest.h>

#include "../support/test_support.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

TEST(RobotCommandPath, KnownSourcesAndFreshStampsOnOwnClock) {
  const auto registry = builtin_registry();
  auto clock = std::make_shared<FakeClock>(5'000'000'000'000);  // far from the wall clock: only this time counts
  auto config = test::test_config();
  config.clock = clock;
  Graph graph(registry, config);
  graph.add("robot", "robot", registry.find("robot")->info.params.resolve({}, "robot"));
  Context ctx("test_commander", test::test_config());
  Publisher<msg::RobotCommand> commands(ctx, topics::kRobotCommand);
  test::Collector<msg::RobotState> states;
  Subscription<msg::RobotState> state_sub(ctx, topics::kRobotState,
                                          [&](const msg::RobotState& s, const SampleMeta&) { states.add(s); });
  ctx.executor().start();
  graph.start();
  ASSERT_TRUE(commands.wait_for_matched(1, 10s));
  ASSERT_TRUE(states.wait([](const auto& v) { return !v.empty(); }, 10s));
  const auto send = [&](const std::string& source, std::int64_t stamp, msg::RobotCommandKind kind) {
    ASSERT_TRUE(commands.publish(robot::command_msg("", kind, 0, Eigen::Vector3d::Zero(), source, stamp)));
    ASSERT_TRUE(commands.wait_for_acks(5s));
  };
  const auto stopped_now = [&](bool want) {
    return states.wait([&](const auto& v) { return v.back().protective_stop() == want; }, 5s);
  };
  // Refused: a stranger's stop, a stop stamped 2 s ago and one 2 s ahead (the robot's clock, not the wall's).
  send("mallory", clock->now_ns(), msg::ROBOT_PROTECTIVE_STOP);
  send("separation", clock->now_ns() - 2'000'000'000, msg::ROBOT_PROTECTIVE_STOP);
  send("separation", clock->now_ns() + 2'000'000'000, msg::ROBOT_PROTECTIVE_STOP);
  // Taken: the monitor's stop stamped now; then an operator's resume half a second old.
  send("separation", clock->now_ns(), msg::ROBOT_PROTECTIVE_STOP);
  ASSERT_TRUE(stopped_now(true));
  clock->advance(500'000'000);
  send("operator", clock->now_ns() - 500'000'000, msg::ROBOT_RESUME);
  ASSERT_TRUE(stopped_now(false));
  graph.stop();
  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  const auto& d = reports[0].details;
  EXPECT_EQ(d["commands"], 2);
  EXPECT_EQ(d["protective_stops"], 1);
  EXPECT_EQ(d["refused_source"], 1);
  EXPECT_EQ(d["refused_stale"], 2);
  EXPECT_NE(d["last_refusal"].get<std::string>().find("ago"), std::string::npos) << d;
  EXPECT_NE(reports[0].message.find("refused 1 command(s) from unknown sources, 2 stale"), std::string::npos)
      << reports[0].message;
}
