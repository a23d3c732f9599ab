// The gesture component on a fake clock, driven through its topics: a
// simulated session it never saw (the build's pointing model, `model: sim`)
// goes in as a skeleton stream; the events that come out are the ones the
// spotting core finds in the same stream (label, span, ray target), each
// person's motion state is published, and a person whose skeleton instance is
// disposed is forgotten with their state.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "../support/temp_dir.hpp"
#include "../support/test_support.hpp"
#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

TEST(GestureComponent, SpotsInAStreamWhatTheCoreSpotsAndForgetsAPersonWhoLeft) {
  const auto sessions = gesture::held_out_sessions(1, 77);
  ASSERT_EQ(sessions.size(), 1u);
  const auto& stream = sessions[0].fused;
  ASSERT_GT(stream.size(), 300u);
  // What the core finds in it with the component's defaults (sim_spotter_options: the cell's).
  const auto expected = gesture::spot_sessions(gesture::load_builtin_model("sim"), sessions)[0].events;
  ASSERT_GE(expected.size(), 3u) << "the session should hold several pointing gestures";

  const auto registry = builtin_registry();
  auto clock = std::make_shared<FakeClock>(9'000'000'000'000);
  auto config = test::test_config();
  config.clock = clock;
  Graph graph(registry, config, 100ms);
  // input=truth: that topic is reliable, so every skeleton of the stream arrives (the fused one is best effort).
  graph.add("gesture", "gesture",
            registry.find("gesture")->info.params.resolve({{"model", "sim", "test"}, {"input", "truth", "test"}}, "gesture"));

  Context ctx("test_cell", config);
  Publisher<msg::Skeleton> skeletons(ctx, topics::kSkeletonTruth);
  test::Collector<msg::GestureEvent> events;
  test::Collector<std::string> states, states_gone;
  Subscription<msg::GestureEvent> event_sub(ctx, topics::kGestureEvent,
                                            [&](const msg::GestureEvent& e, const SampleMeta&) { events.add(e); });
  Subscription<msg::GestureState> state_sub(
      ctx, topics::kGestureState, [&](const msg::GestureState& s, const SampleMeta&) { states.add(s.state().to_string()); },
      [&](const msg::GestureState& last, const SampleMeta&) { states_gone.add(last.source().to_string()); });
  ctx.executor().start();
  graph.start();
  ASSERT_TRUE(skeletons.wait_for_matched(1, 10s));
  ASSERT_TRUE(event_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(state_sub.wait_for_matched(1, 10s));

  // The stream in batches of 16, each taken by the component before the next
  // (reliable and in order; its reader keeps the last 64 it has not taken).
  const auto& gesture_ctx = graph.context("gesture");
  for (std::size_t i = 0; i < stream.size(); ++i) {
    ASSERT_TRUE(skeletons.publish(skeleton::to_msg(stream[i])));
    if (i % 16 == 15 || i + 1 == stream.size()) {
      ASSERT_TRUE(test::wait_input_count(gesture_ctx, topics::kSkeletonTruth.name, i + 1, 20s)) << "at skeleton " << i;
    }
  }
  ASSERT_TRUE(events.wait_count(expected.size(), 20s)) << events.items().size() << " of " << expected.size() << " events";

  const auto got = events.items();
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    SCOPED_TRACE("event " + std::to_string(i));
    EXPECT_EQ(got[i].label(), expected[i].label);
    EXPECT_EQ(got[i].person_id(), expected[i].person_id);
    EXPECT_EQ(got[i].source(), stream.front().sensor_id);
    EXPECT_EQ(got[i].start_stamp_ns(), expected[i].start_ns);
    EXPECT_EQ(got[i].end_stamp_ns(), expected[i].end_ns);
    EXPECT_EQ(got[i].has_target(), expected[i].has_target);
    EXPECT_NEAR(got[i].confidence(), expected[i].confidence, 1e-9);
    if (expected[i].has_target) {
      EXPECT_NEAR(got[i].target().x(), expected[i].target.x(), 1e-9);
      EXPECT_NEAR(got[i].target().y(), expected[i].target.y(), 1e-9);
      EXPECT_NEAR(got[i].target().z(), expected[i].target.z(), 1e-9);
      EXPECT_EQ(got[i].target_name(), "floor");
    }
  }
  // The person's motion changed during the session: its states were published.
  EXPECT_TRUE(states.wait([](const auto& v) { return v.size() >= 2; }, 10s)) << states.items().size();

  // The person leaves (the skeleton instance disposed): their state is disposed too.
  msg::Skeleton key;
  key.sensor_id(stream.front().sensor_id);
  key.person_id(stream.front().person_id);
  ASSERT_TRUE(skeletons.dispose(key));
  ASSERT_TRUE(states_gone.wait_count(1, 10s));
  EXPECT_EQ(states_gone.items()[0], stream.front().sensor_id);
  graph.stop();

  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  const auto& d = reports[0].details;
  EXPECT_EQ(d["skeletons"], stream.size()) << d;
  EXPECT_EQ(d["events"], expected.size()) << d;
  EXPECT_EQ(d["people_seen"], 1) << d;
  EXPECT_EQ(d["people_left"], 1) << d;
  EXPECT_EQ(d["people"], 0) << d;
}

TEST(GestureComponent, CutsWhereTheModelSaysUnlessItsParametersSay) {
  auto model = gesture::load_builtin_model("sim");
  model.set_operating_point({0.4, 0.5});
  const auto path = test::fresh_path("gesture_operating_point.json");
  model.save(path.string());
  const auto registry = builtin_registry();
  const auto cut = [&](std::vector<RawParam> raw) {
    raw.push_back({"model", path.string(), "test"});
    Graph graph(registry, test::test_config(), 100ms);
    graph.add("gesture", "gesture", registry.find("gesture")->info.params.resolve(raw, "gesture"));
    graph.start();
    graph.stop();
    return graph.report().at(0).details.at("operating_point");
  };
  const auto own = cut({});
  EXPECT_EQ(own["min_confidence"], 0.4) << own;
  EXPECT_EQ(own["confirm_s"], 0.5) << own;
  const auto given = cut({{"min_confidence", "0.1", "test"}, {"confirm_s", "0", "test"}});
  EXPECT_EQ(given["min_confidence"], 0.1) << given;
  EXPECT_EQ(given["confirm_s"], 0.0) << given;
  std::filesystem::remove(path);
}
