// The depth tracker component on a fake clock, driven through its topics: a
// simulated cell's depth images of two calibrated sensors go in; the raw
// skeletons and frame heartbeats that come out are what the tracking core
// makes of the same images, one tracker per sensor or, with `merge`, one
// fitting both sensors' views of each moment (the lead's images with the
// other's latest within 40 ms by the component's clock). A sensor without a
// pose waits and says so.

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <tuple>

#include "../support/test_support.hpp"
#include "skelgraph/depth/depth_msg.hpp"
#include "skelgraph/depth_tracker/frame_matcher.hpp"
#include "skelgraph/depth_tracker/tracker.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/sim/depth_render.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

namespace {

struct Cell {
  std::vector<skeleton::SensorPose> poses;
  std::vector<depth::DepthImage> images;  // both sensors', in time order
};

// 1.5 s of the simulator's walking person seen by its two default sensors, 160x120 images.
Cell simulated_cell() {
  sim::SimConfig config;
  config.scenario.name = "walk";
  config.emit_frames = true;
  config.epoch_ns = 20'000'000'000'000;
  sim::Simulation sim(config);
  Cell cell;
  std::vector<sim::DepthRenderer> renderers;
  std::vector<sim::Rng> rngs;
  const sim::Rng base(config.scenario.seed);
  for (std::size_t i = 0; i < config.sensors.size(); ++i) {
    renderers.emplace_back(config.sensors[i], depth::kinect_intrinsics(160, 120));
    rngs.push_back(base.fork(0xde97000 + i));
    skeleton::SensorPose p;
    p.sensor_id = config.sensors[i].id;
    p.pose = config.sensors[i].world_from_sensor();
    cell.poses.push_back(p);
  }
  for (auto& e : sim.advance(1.5)) {
    if (e.kind != sim::SimEvent::Kind::Frame) continue;
    auto image = renderers[e.sensor].render(sim.truth_at(e.t), sim.scenario().at(e.t).obstacles, rngs[e.sensor],
                                            config.scenario.height);
    image.stamp_ns = e.skeleton.stamp_ns;
    image.frame_number = e.skeleton.frame_number;
    cell.images.push_back(std::move(image));
  }
  return cell;
}

using Key = std::tuple<std::string, std::int64_t, std::uint32_t>;  // sensor, stamp, person

// What the core makes of the images: one tracker per sensor, or one for
// merged views (the first sensor's images lead, the matcher's clock the
// images' stamps, as the test's clock is set to each before it is sent).
std::map<Key, skeleton::Skeleton> core_skeletons(const Cell& cell, bool merge) {
  std::map<Key, skeleton::Skeleton> out;
  std::map<std::string, Eigen::Isometry3d> pose;
  for (const auto& p : cell.poses) pose[p.sensor_id] = p.pose;
  std::map<std::string, depth_tracker::DepthTracker> trackers;
  depth_tracker::DepthTracker merged{depth_tracker::TrackerOptions{}};
  depth_tracker::FrameMatcher<std::string> moments;
  for (auto image : cell.images) {
    std::vector<skeleton::Skeleton> people;
    if (!merge) {
      auto it = trackers.find(image.sensor_id);
      if (it == trackers.end()) {
        it = trackers.emplace(image.sensor_id, depth_tracker::DepthTracker{depth_tracker::TrackerOptions{}}).first;
        it->second.set_pose(pose.at(image.sensor_id));
      }
      people = it->second.track(image);
    } else {
      const auto sensor = image.sensor_id;
      const auto t = image.stamp_ns;
      const auto views = moments.add(sensor, t, std::move(image));
      if (views.empty()) continue;
      std::vector<depth::DepthImage> images;
      std::vector<Eigen::Isometry3d> poses;
      for (const auto& v : views) {
        images.push_back(*v.image);
        poses.push_back(pose.at(v.sensor));
      }
      people = merged.track_merged(images, poses, "merged");
    }
    for (auto& s : people) out[{s.sensor_id, s.stamp_ns, s.person_id}] = std::move(s);
  }
  return out;
}

// Runs the component on the cell's images (each taken before the next: the
// depth topic is best effort, two deep) and returns its raw skeletons and
// heartbeats, and its report.
struct Run {
  std::map<Key, skeleton::Skeleton> skeletons;
  std::map<std::string, int> frames;  // heartbeats per sensor_id
  nlohmann::json details;
  std::vector<std::string> messages;  // its status messages
};
Run run_component(const Cell& cell, bool merge, bool publish_poses) {
  Run run;
  auto clock = std::make_shared<FakeClock>(cell.images.front().stamp_ns);
  auto config = test::test_config();
  config.clock = clock;
  const auto registry = builtin_registry();
  Graph graph(registry, config, 100ms);
  graph.add("tracker", "depth_tracker",
            registry.find("depth_tracker")->info.params.resolve({{"merge", merge ? "true" : "false", "test"}}, "tracker"));
  Context ctx("test_cell", config);
  Publisher<msg::SensorPose> poses(ctx, topics::kCalibration);
  Publisher<msg::DepthFrame> depth(ctx, topics::kDepth);
  test::Collector<skeleton::Skeleton> raw;
  test::Collector<std::string> frames, status;
  auto qos = topics::kSkeletonRaw.qos;
  qos.depth = 256;  // best effort as published, room for all
  Subscription<msg::Skeleton> raw_sub(ctx, topics::kSkeletonRaw, qos,
                                      [&](const msg::Skeleton& m, const SampleMeta&) { raw.add(skeleton::from_msg(m)); });
  auto frame_qos = topics::kSensorFrame.qos;
  frame_qos.depth = 256;
  Subscription<msg::SensorFrame> frame_sub(ctx, topics::kSensorFrame, frame_qos,
                                           [&](const msg::SensorFrame& f, const SampleMeta&) { frames.add(f.sensor_id().to_string()); });
  Subscription<msg::ComponentStatus> status_sub(ctx, topics::kStatus, [&](const msg::ComponentStatus& m, const SampleMeta&) {
    if (m.component_name() == "tracker") status.add(m.message().to_string());
  });
  ctx.executor().start();
  graph.start();
  const auto& tracker_ctx = graph.context("tracker");
  EXPECT_TRUE(depth.wait_for_matched(1, 10s));
  EXPECT_TRUE(test::wait_input_matched(tracker_ctx, topics::kDepth.name));  // best effort: the first image would be lost
  EXPECT_TRUE(raw_sub.wait_for_matched(1, 10s));
  EXPECT_TRUE(frame_sub.wait_for_matched(1, 10s));
  if (publish_poses) {
    for (const auto& p : cell.poses) poses.publish(skeleton::to_msg(p));
    EXPECT_TRUE(test::wait_input_count(tracker_ctx, topics::kCalibration.name, cell.poses.size() + (merge ? 1 : 0)));
  }
  std::uint64_t sent = 0;
  for (const auto& image : cell.images) {
    clock->set(image.stamp_ns);
    depth.publish(depth::to_msg(image));
    if (!test::wait_input_count(tracker_ctx, topics::kDepth.name, ++sent, 30s)) {
      ADD_FAILURE() << "image " << sent << " not taken";
      break;
    }
  }
  // Every image's heartbeat (merged: every fit's) is out once the last is; wait for them to arrive.
  const auto heartbeats = merge ? cell.images.size() / 2 : cell.images.size();
  if (publish_poses) {
    EXPECT_TRUE(frames.wait_count(heartbeats, 10s)) << frames.items().size() << " of " << heartbeats;
    // Every skeleton written has arrived (best effort, but paced and with room for all).
    const auto written = [&] {
      for (const auto& c : tracker_ctx.counters()) {
        if (c->is_output && c->topic == topics::kSkeletonRaw.name) return c->count.load();
      }
      return std::uint64_t{0};
    }();
    EXPECT_TRUE(raw.wait_count(written, 10s)) << raw.items().size() << " of " << written;
  }
  status.wait([](const auto& v) { return !v.empty(); }, 5s);
  graph.stop();
  for (auto& s : raw.items()) run.skeletons[{s.sensor_id, s.stamp_ns, s.person_id}] = s;
  for (const auto& f : frames.items()) ++run.frames[f];
  run.details = graph.report()[0].details;
  run.messages = status.items();
  return run;
}

void expect_same(const std::map<Key, skeleton::Skeleton>& got, const std::map<Key, skeleton::Skeleton>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (const auto& [key, w] : want) {
    const auto it = got.find(key);
    ASSERT_NE(it, got.end()) << std::get<0>(key) << " at " << std::get<1>(key) << " person " << std::get<2>(key);
    EXPECT_EQ(it->second.frame_id, w.frame_id);
    EXPECT_EQ(it->second.frame_number, w.frame_number);
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      EXPECT_LT((it->second.joints[j].position - w.joints[j].position).norm(), 1e-9) << std::get<1>(key) << " joint " << j;
      EXPECT_EQ(it->second.joints[j].confidence, w.joints[j].confidence);
    }
  }
}

}  // namespace

TEST(DepthTrackerComponent, TracksEachSensorAsTheCoreDoes) {
  const auto cell = simulated_cell();
  ASSERT_GE(cell.images.size(), 80u);
  const auto want = core_skeletons(cell, false);
  ASSERT_GE(want.size(), 30u) << "the walking person should be tracked in most images";
  const auto run = run_component(cell, false, true);
  expect_same(run.skeletons, want);
  EXPECT_EQ(run.frames.at("sensor1") + run.frames.at("sensor2"), static_cast<int>(cell.images.size()));
  EXPECT_EQ(run.details["sensors"].size(), 2u) << run.details;
}

TEST(DepthTrackerComponent, MergedViewsAreFittedAsTheCoreFitsThem) {
  const auto cell = simulated_cell();
  const auto want = core_skeletons(cell, true);
  ASSERT_GE(want.size(), 15u);
  for (const auto& [key, s] : want) ASSERT_EQ(s.frame_id, "world");
  const auto run = run_component(cell, true, true);
  expect_same(run.skeletons, want);
  EXPECT_EQ(run.frames.size(), 1u);  // heartbeats as sensor "merged" only
  EXPECT_GT(run.frames.at("merged"), 0);
}

TEST(DepthTrackerComponent, WithoutAPoseItWaitsAndSaysSo) {
  auto cell = simulated_cell();
  cell.images.resize(10);
  const auto run = run_component(cell, false, false);
  EXPECT_TRUE(run.skeletons.empty());
  ASSERT_FALSE(run.messages.empty());
  EXPECT_NE(run.messages.back().find("waiting for the pose of sensor"), std::string::npos) << run.messages.back();
}
