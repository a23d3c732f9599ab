// The sync_master component with local participants: START, ticks at the set
// period, STOP; control requests; late joiners. Runs in a loopback-only namespace.

#include <gtest/gtest.h>

#include "../support/test_support.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

namespace {

Params sync_params(double period_ms, bool autostart, const std::string& label = "test") {
  RawParam p{"tick_period_ms", std::to_string(period_ms), "test"};
  RawParam a{"autostart", autostart ? "true" : "false", "test"};
  RawParam l{"label", label, "test"};
  return builtin_registry().find("sync_master")->info.params.resolve({p, a, l}, "sync");
}

struct Listener {
  Context ctx{"test_listener", test::test_config()};
  test::Collector<msg::SyncCommand> sync;
  test::Collector<msg::SyncCommand> session;
  Subscription<msg::SyncCommand> sync_sub{ctx, topics::kSync,
                                          [this](const msg::SyncCommand& c, const SampleMeta&) { sync.add(c); }};
  Subscription<msg::SyncCommand> session_sub{
      ctx, topics::kSyncSession, [this](const msg::SyncCommand& c, const SampleMeta&) { session.add(c); }};
  Listener() { ctx.executor().start(); }
};

// Waits until the component's writer on `topic` has matched a reader (the
// writer's side of matching, which a reader's own match does not imply).
bool writer_matched(Context& ctx, const std::string& topic) {
  for (const auto& c : ctx.counters()) {
    if (c->is_output && c->topic == topic) return c->wait_matched(1, std::chrono::seconds(10));
  }
  return false;
}

std::vector<msg::SyncCommand> of_kind(const std::vector<msg::SyncCommand>& v, msg::SyncKind k) {
  std::vector<msg::SyncCommand> out;
  for (const auto& c : v) {
    if (c.kind() == k) out.push_back(c);
  }
  return out;
}

}  // namespace

TEST(SyncMaster, StartTicksAtPeriodThenStop) {
  const auto registry = builtin_registry();
  Listener listener;
  Graph graph(registry, test::test_config());
  graph.add("sync", "sync_master", sync_params(20.0, true, "walk"));
  // Match before starting so the START on skelgraph/sync cannot be missed.
  ASSERT_TRUE(listener.sync_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(writer_matched(graph.context("sync"), topics::kSync.name));
  graph.start();
  constexpr std::size_t kTicks = 50;
  ASSERT_TRUE(listener.sync.wait([](const auto& v) { return of_kind(v, msg::SYNC_TICK).size() >= kTicks; }, 20s));
  graph.stop();
  ASSERT_TRUE(listener.sync.wait([](const auto& v) { return !of_kind(v, msg::SYNC_STOP).empty(); }, 10s));

  const auto all = listener.sync.items();
  ASSERT_EQ(all.front().kind(), msg::SYNC_START);
  EXPECT_EQ(all.front().label().to_string(), "walk");
  const auto ticks = of_kind(all, msg::SYNC_TICK);
  const auto stop = of_kind(all, msg::SYNC_STOP);
  ASSERT_EQ(stop.size(), 1u);
  EXPECT_EQ(all.back().kind(), msg::SYNC_STOP);
  // Reliable: every tick, in order, none twice; STOP names the last one.
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_EQ(ticks[i].tick(), i + 1);
    EXPECT_EQ(ticks[i].session_id(), all.front().session_id());
  }
  EXPECT_EQ(stop[0].tick(), ticks.size());
  EXPECT_EQ(stop[0].session_id(), all.front().session_id());
  // The period, from the master's own stamps over the whole run.
  const double period_ms = static_cast<double>(ticks.back().master_stamp_ns() - ticks.front().master_stamp_ns()) /
                           static_cast<double>(ticks.back().tick() - ticks.front().tick()) / 1e6;
  EXPECT_NEAR(period_ms, 20.0, 3.0);
  // The session topic carried START and STOP only.
  ASSERT_TRUE(listener.session.wait_count(2));
  EXPECT_EQ(listener.session.items()[0].kind(), msg::SYNC_START);
  EXPECT_EQ(listener.session.items()[1].kind(), msg::SYNC_STOP);
}

TEST(SyncMaster, ControlRequestsStartAndStopSessions) {
  const auto registry = builtin_registry();
  Listener listener;
  Graph graph(registry, test::test_config());
  graph.add("sync", "sync_master", sync_params(10.0, false));
  graph.start();
  Context cli("test_cli", test::test_config());
  Publisher<msg::SyncControl> control(cli, topics::kSyncControl);
  ASSERT_TRUE(control.wait_for_matched(1, 10s));
  ASSERT_TRUE(listener.session_sub.wait_for_matched(1, 10s));

  msg::SyncControl start;
  start.kind(msg::SYNC_START);
  start.label("box");
  start.request_id("r1");
  ASSERT_TRUE(control.publish(start));
  ASSERT_TRUE(listener.session.wait_count(1));
  EXPECT_EQ(listener.session.items()[0].kind(), msg::SYNC_START);
  EXPECT_EQ(listener.session.items()[0].label().to_string(), "box");
  EXPECT_EQ(listener.session.items()[0].request_id().to_string(), "r1");
  ASSERT_TRUE(listener.sync.wait([](const auto& v) { return of_kind(v, msg::SYNC_TICK).size() >= 5; }));

  msg::SyncControl stop;
  stop.kind(msg::SYNC_STOP);
  stop.request_id("r2");
  ASSERT_TRUE(control.publish(stop));
  ASSERT_TRUE(listener.session.wait_count(2));
  const auto s = listener.session.items()[1];
  EXPECT_EQ(s.kind(), msg::SYNC_STOP);
  EXPECT_EQ(s.request_id().to_string(), "r2");
  EXPECT_EQ(s.session_id(), listener.session.items()[0].session_id());
  // After STOP no more ticks: everything on the sync topic ends with that STOP.
  ASSERT_TRUE(listener.sync.wait([](const auto& v) { return !of_kind(v, msg::SYNC_STOP).empty(); }));
  ASSERT_TRUE(graph.context("sync").executor().run_sync([] {}, 5s));
  ASSERT_TRUE(listener.ctx.executor().run_sync([] {}, 5s));
  EXPECT_EQ(listener.sync.items().back().kind(), msg::SYNC_STOP);
}

TEST(SyncMaster, LateJoinerLearnsTheRunningSession) {
  const auto registry = builtin_registry();
  Graph graph(registry, test::test_config());
  graph.add("sync", "sync_master", sync_params(33.0, true, "late"));
  graph.start();
  // Joins after START was sent (and after some ticks).
  Context probe("probe", test::test_config());
  test::Collector<msg::SyncCommand> ticks;
  Subscription<msg::SyncCommand> tick_sub(probe, topics::kSync,
                                          [&](const msg::SyncCommand& c, const SampleMeta&) { ticks.add(c); });
  probe.executor().start();
  ASSERT_TRUE(ticks.wait_count(3));
  Context late("late_recorder", test::test_config());
  test::Collector<msg::SyncCommand> got;
  Subscription<msg::SyncCommand> sub(late, topics::kSyncSession,
                                     [&](const msg::SyncCommand& c, const SampleMeta&) { got.add(c); });
  late.executor().start();
  ASSERT_TRUE(got.wait_count(1));
  EXPECT_EQ(got.items()[0].kind(), msg::SYNC_START);
  EXPECT_EQ(got.items()[0].label().to_string(), "late");
  EXPECT_EQ(got.items()[0].session_id(), ticks.items()[0].session_id());
}

TEST(Graph, ComponentErrorsNameTheComponent) {
  const auto registry = builtin_registry();
  Graph graph(registry, test::test_config());
  EXPECT_THROW(graph.add("x", "no_such_kind", Params{}), std::runtime_error);
  graph.add("sync", "sync_master", sync_params(33.0, false));
  try {
    graph.add("sync", "sync_master", sync_params(33.0, false));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'sync' used twice"), std::string::npos);
  }
  // Params missing a declared key: the component's constructor throws; the graph says whose.
  try {
    graph.add("broken", "sync_master", Params{});
    FAIL();
  } catch (const std::logic_error& e) {
    FAIL() << "logic_error escaped unwrapped: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("component 'broken' (sync_master)"), std::string::npos) << e.what();
  }
}

// The graph starts its components only once they hear each other: a fusion
// component composed with the sync master gets the session from its START,
// every tick of it and the STOP, although nothing here waits for discovery
// (before, a session began at once and a reader that matched late never saw
// the first ticks: the demo's kalman once heard none in 6 s on a busy CI machine).
TEST(Graph, StartsOnceItsComponentsHaveMatchedEachOther) {
  const auto registry = builtin_registry();
  Graph graph(registry, test::test_config());
  auto sp = builtin_registry().find("sync_master")->info.params.resolve(
      {{"tick_period_ms", "20", "test"}, {"label", "first", "test"}, {"session_duration_s", "1", "test"}}, "sync");
  graph.add("sync", "sync_master", sp);
  graph.add("fusion", "fusion",
            registry.find("fusion")->info.params.resolve({{"method", "avg", "test"}, {"trigger", "ticks", "test"}},
                                                         "fusion"));
  graph.start();
  EXPECT_TRUE(graph.await_matches(0ms).empty()) << "start() returned before the graph's endpoints matched";
  // START, 50 ticks (1 s at 20 ms) and the STOP: 52 commands written, all 52 taken.
  constexpr std::uint64_t kCommands = 52;
  EXPECT_TRUE(test::wait_endpoint_count(graph.context("sync"), test::Endpoint::Output, topics::kSync.name, kCommands,
                                        20s));
  EXPECT_TRUE(test::wait_input_count(graph.context("fusion"), topics::kSync.name, kCommands, 20s));
  graph.stop();
  nlohmann::json sync, fusion;
  for (const auto& r : graph.report()) (r.name == "sync" ? sync : fusion) = r.details;
  EXPECT_EQ(sync["ticks_sent"].get<int>(), 50) << sync;
  EXPECT_EQ(fusion["tick_steps"].get<int>(), 50) << fusion;
}
