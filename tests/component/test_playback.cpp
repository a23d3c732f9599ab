// The playback component replays a file on skelgraph/skeleton/raw.

#include <gtest/gtest.h>

#include <fstream>

#include "../support/test_support.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

TEST(Playback, ReplaysAGenericCsvAsALiveStream) {
  playback::Recording rec;
  for (int i = 0; i < 30; ++i) {
    skeleton::Skeleton s;
    s.sensor_id = "recorded";
    s.person_id = 2;
    s.frame_id = "recorded";
    s.stamp_ns = 1'000'000'000LL + i * 33'333'333LL;
    s.frame_number = static_cast<std::uint64_t>(i);
    s[skeleton::JointId::RightHand].position = {0.01 * i, 1.2, 2.0};
    s[skeleton::JointId::RightHand].confidence = 1.0f;
    rec.frames.push_back(s);
  }
  const auto path = ::testing::TempDir() + "/playback.csv";
  {
    std::ofstream out(path);
    playback::write_generic_csv(rec, out);
  }
  const auto registry = builtin_registry();
  const auto params = registry.find("playback")->info.params.resolve(
      {{"format", "generic", "test"}, {"files", std::vector<std::string>{path}, "test"}, {"rate", "2", "test"}},
      "playback");

  Context listener("listener", test::test_config());
  test::Collector<msg::Skeleton> got;
  // Best effort as published, but a history of all 30: a listener whose
  // executor is starved for a moment on a busy machine still gets every frame.
  auto qos = topics::kSkeletonRaw.qos;
  qos.depth = 64;
  Subscription<msg::Skeleton> sub(listener, topics::kSkeletonRaw, qos,
                                  [&](const msg::Skeleton& s, const SampleMeta&) { got.add(s); });
  listener.executor().start();
  Graph graph(registry, test::test_config());
  graph.add("play", "playback", params);
  for (const auto& c : graph.context("play").counters()) {
    if (c->is_output && c->topic == topics::kSkeletonRaw.name) {
      ASSERT_TRUE(c->wait_matched(1, 10s));
    }
  }
  // Best effort: the writer may match the reader before the reader matches the
  // writer, and frames sent in between are lost (a clean-clone run got 26 of 30).
  ASSERT_TRUE(sub.wait_for_matched(1, 10s));
  const auto before = system_clock()->now_ns();
  graph.start();
  ASSERT_TRUE(got.wait_count(30, 20s)) << got.items().size() << " of 30 frames";
  graph.stop();
  const auto items = got.items();
  for (std::size_t i = 0; i < items.size(); ++i) {
    EXPECT_EQ(items[i].frame_number(), i);
    EXPECT_EQ(items[i].sensor_id().to_string(), "recorded");
    EXPECT_EQ(items[i].person_id(), 2u);
    EXPECT_DOUBLE_EQ(items[i].joints()[msg::JOINT_RIGHT_HAND].position().x(), 0.01 * static_cast<double>(i));
    // Re-stamped to the playback clock, at twice the recorded speed.
    EXPECT_GE(items[i].stamp_ns(), before);
    if (i > 0) {
      EXPECT_NEAR(static_cast<double>(items[i].stamp_ns() - items[i - 1].stamp_ns()), 33'333'333 / 2.0, 1.0)
          << "frame " << i;
    }
  }
  const auto report = graph.report();
  EXPECT_EQ(report[0].details["published"], 30);
  EXPECT_EQ(report[0].details["finished"], true);
}

TEST(Playback, BadFileRefusesToStartNamingFileAndLine) {
  const auto path = ::testing::TempDir() + "/bad_playback.csv";
  std::ofstream(path) << "# skelgraph skeleton csv v1\nstamp_ns,sensor_id\n";
  const auto registry = builtin_registry();
  const auto params = registry.find("playback")->info.params.resolve(
      {{"files", std::vector<std::string>{path}, "test"}}, "playback");
  Graph graph(registry, test::test_config());
  try {
    graph.add("play", "playback", params);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad_playback.csv:2: missing column 'person_id'"), std::string::npos)
        << e.what();
  }
}
