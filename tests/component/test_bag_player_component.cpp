// The bag player component on a fake clock, driven through its topics: it
// paces a recording by the clock it runs on (nothing is due until the test's
// clock says so), puts messages a little out of order in the file back in
// order, and obeys pause, step, seek and resume on skelgraph/play/control,
// each answered on skelgraph/play/state; a seek republishes the latest sensor
// pose before the new position. The recording's end finishes the component.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "../support/test_support.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

namespace {
constexpr std::uint64_t kT0 = 1'700'000'000'000'000'000ULL;
constexpr std::uint64_t kFrameNs = 100'000'000;  // 10 Hz
constexpr int kFrames = 50;

// A sensor pose at the start, then 50 skeletons of sensor1 100 ms apart
// (frame number = index); frames 5 and 6 swapped in the file.
std::string write_recording() {
  const auto path = (std::filesystem::path(::testing::TempDir()) / "bag_player_component.mcap").string();
  recording::BagWriter bag(path);
  skeleton::SensorPose pose;
  pose.sensor_id = "sensor1";
  pose.pose.translation() = Eigen::Vector3d(0, 1.2, 2);
  bag.write(topics::kCalibration.name, skeleton::to_msg(pose), kT0, kT0);
  for (int k = 0; k < kFrames; ++k) {
    const int i = k == 5 ? 6 : k == 6 ? 5 : k;
    skeleton::Skeleton s;
    s.sensor_id = "sensor1";
    s.person_id = 1;
    s.frame_id = "sensor1";
    s.frame_number = static_cast<std::uint64_t>(i);
    s.stamp_ns = static_cast<std::int64_t>(kT0 + i * kFrameNs);
    s[skeleton::JointId::Torso].position = {0.01 * i, 1.0, 2.0};
    s[skeleton::JointId::Torso].confidence = skeleton::kTracked;
    bag.write(topics::kSkeletonRaw.name, skeleton::to_msg(s), kT0 + i * kFrameNs, kT0 + i * kFrameNs);
  }
  bag.close();
  return path;
}
}  // namespace

TEST(BagPlayerComponent, PacesByItsClockAndObeysPauseStepSeekAndResume) {
  const auto file = write_recording();
  auto clock = std::make_shared<FakeClock>(50'000'000'000);
  auto config = test::test_config();
  config.clock = clock;
  const auto registry = builtin_registry();
  Graph graph(registry, config, 100ms);
  graph.add("player", "bag_player",
            registry.find("bag_player")->info.params.resolve({{"file", file, "test"}, {"wait_s", "5", "test"}}, "bag_player"));

  Context ctx("test_viewer", config);
  auto qos = topics::kSkeletonRaw.qos;
  qos.depth = 64;  // best effort as played, but room for every frame however late this test's executor runs
  test::Collector<std::uint64_t> frames;
  test::Collector<std::string> poses;
  test::Collector<msg::PlayState> states;
  Subscription<msg::Skeleton> raw_sub(ctx, topics::kSkeletonRaw, qos,
                                      [&](const msg::Skeleton& s, const SampleMeta&) { frames.add(s.frame_number()); });
  Subscription<msg::SensorPose> pose_sub(ctx, topics::kCalibration,
                                         [&](const msg::SensorPose& p, const SampleMeta&) { poses.add(p.sensor_id().to_string()); });
  Subscription<msg::PlayState> state_sub(ctx, topics::kPlayState,
                                         [&](const msg::PlayState& s, const SampleMeta&) { states.add(s); });
  Publisher<msg::PlayControl> control(ctx, topics::kPlayControl);
  ctx.executor().start();
  graph.start();
  ASSERT_TRUE(raw_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(pose_sub.wait_for_matched(1, 10s));
  ASSERT_TRUE(control.wait_for_matched(1, 10s));

  // A request, repeated until the player's state answers it.
  int requests = 0;
  const auto request = [&](msg::PlayKind kind, double value) {
    const std::string id = "r" + std::to_string(++requests);
    msg::PlayControl c;
    c.target("player");
    c.kind(kind);
    c.value(value);
    c.request_id(id);
    for (int i = 0; i < 100; ++i) {
      control.publish(c);
      if (states.wait([&](const auto& v) { return !v.empty() && v.back().request_id() == id; }, 100ms)) break;
    }
    const auto last = states.items().back();
    EXPECT_EQ(last.request_id(), id);
    EXPECT_EQ(last.error(), "") << last.error();
    return last;
  };
  const auto frames_are = [&](std::uint64_t first, std::uint64_t last, std::size_t from_index) {
    const auto got = frames.items();
    std::vector<std::uint64_t> want, have(got.begin() + static_cast<std::ptrdiff_t>(std::min(from_index, got.size())), got.end());
    for (auto f = first; f <= last; ++f) want.push_back(f);
    EXPECT_EQ(have, want);
  };

  // The player waits for its readers, then 0.5 s on its clock: nothing plays
  // until the clock moves. Moved on in small steps until the first frame
  // (due with the pose, at the start) is out: its pacing starts there.
  for (int i = 0; i < 100 && !frames.wait_count(1, 100ms); ++i) clock->advance(100'000'000);
  ASSERT_TRUE(frames.wait_count(1, 1s));
  ASSERT_TRUE(poses.wait_count(1, 10s));
  // One second on the player's clock: frames 0..10 are due (5 and 6 in order), and no more.
  clock->advance(1'000'000'000);
  ASSERT_TRUE(frames.wait_count(11, 10s)) << frames.items().size();
  auto st = request(msg::PLAY_PAUSE, 0);
  EXPECT_TRUE(st.paused());
  frames_are(0, 10, 0);

  // Paused, three steps deliver frames 11..13 at once, whatever the clock.
  st = request(msg::PLAY_STEP, 3);
  // Answered once they are sent; received a moment later.
  ASSERT_TRUE(frames.wait_count(14, 10s)) << ::testing::PrintToString(frames.items()) << "; the player says " << st.frames();
  EXPECT_EQ(st.frames(), 15u);  // the pose and 14 frames
  EXPECT_NEAR(st.position_s(), 1.3, 1e-9);
  EXPECT_NEAR(st.duration_s(), 4.9, 1e-9);

  // Seek to 3 s: the pose before it is published again, the frames before it are skipped.
  st = request(msg::PLAY_SEEK, 3.0);
  EXPECT_NEAR(st.position_s(), 3.0, 1e-9);
  ASSERT_TRUE(poses.wait_count(2, 10s));
  const auto before_resume = frames.items().size();
  request(msg::PLAY_RESUME, 0);
  // Resumed, the player paces afresh from frame 30 (due at once) at the clock's time then.
  ASSERT_TRUE(frames.wait_count(before_resume + 1, 10s));
  clock->advance(2'000'000'000);  // 3.0 .. 5.0 s: frames 31..49, the end
  ASSERT_TRUE(frames.wait_count(before_resume + 20, 10s)) << frames.items().size();
  frames_are(30, 49, before_resume);
  ASSERT_TRUE(states.wait([](const auto& v) { return v.back().at_end(); }, 10s));
  for (int i = 0; i < 1000 && !graph.finished(); ++i) std::this_thread::sleep_for(10ms);  // polling the condition
  EXPECT_TRUE(graph.finished());
  graph.stop();

  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  const auto& d = reports[0].details;
  EXPECT_EQ(d["messages"], kFrames + 1) << d;
  EXPECT_EQ(d["published"], 1 + 14 + 20) << d;  // the pose, 0..13, 30..49 (the pose again at the seek is state, not counted)
  EXPECT_EQ(d["played_late"], 0) << d;
  EXPECT_EQ(d["failed"], 0) << d;
}
