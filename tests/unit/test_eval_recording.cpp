// Recordings through the evaluator (eval/recording.hpp): what a file holds,
// its skeletons in time order whatever the file's own order (within its
// lateness), scored exactly as the same events handed over sorted, fused into
// a copy with nothing lost, and clear errors for what cannot be scored.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include "skelgraph/eval/recording.hpp"
#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;

namespace {

struct Written {
  std::vector<eval::TimedSkeleton> events;  // in time order
  std::map<std::string, Eigen::Isometry3d> poses;
  std::int64_t max_shuffle_ns = 0;
};

// A few seconds of the simulated cell, written with each skeleton's log time
// its event time, but in a file order shuffled within windows of `shuffle`
// messages (as a recorder taking several streams writes them).
Written write_recording(const std::string& path, std::size_t shuffle, bool with_poses = true) {
  sim::SimConfig cfg;
  cfg.scenario.name = "walk";
  cfg.epoch_ns = 1'700'000'000'000'000'000LL;
  sim::Simulation sim(cfg);
  Written w;
  for (auto& e : sim.advance(6.0)) {
    const auto t = cfg.epoch_ns + static_cast<std::int64_t>(std::llround(e.t * 1e9));
    w.events.push_back({e.kind == sim::SimEvent::Kind::Truth ? eval::TimedSkeleton::Kind::Truth : eval::TimedSkeleton::Kind::Raw,
                        t, std::move(e.skeleton)});
  }
  auto order = w.events;
  std::mt19937 rng(7);
  for (std::size_t i = 0; i + shuffle <= order.size(); i += shuffle) {
    std::shuffle(order.begin() + static_cast<std::ptrdiff_t>(i), order.begin() + static_cast<std::ptrdiff_t>(i + shuffle), rng);
  }
  std::int64_t latest = 0;
  for (const auto& e : order) {
    latest = std::max(latest, e.t_ns);
    w.max_shuffle_ns = std::max(w.max_shuffle_ns, latest - e.t_ns);
  }
  recording::BagWriter bag(path);
  if (with_poses) {
    for (const auto& s : cfg.sensors) {
      skeleton::SensorPose p;
      p.sensor_id = s.id;
      p.pose = s.world_from_sensor();
      w.poses[s.id] = p.pose;
      bag.write("skelgraph/calibration", skeleton::to_msg(p), static_cast<std::uint64_t>(cfg.epoch_ns), 0);
    }
  }
  for (const auto& e : order) {
    const auto topic = e.kind == eval::TimedSkeleton::Kind::Truth ? "skelgraph/skeleton/truth" : "skelgraph/skeleton/raw";
    bag.write(topic, skeleton::to_msg(e.skeleton), static_cast<std::uint64_t>(e.t_ns), static_cast<std::uint64_t>(e.t_ns));
  }
  bag.close();
  return w;
}

std::string temp(const std::string& name) { return (std::filesystem::temp_directory_path() / name).string(); }

}  // namespace

TEST(EvalRecording, AShuffledRecordingScoresAsItsEventsInTimeOrder) {
  const auto file = temp("skelgraph_eval_recording_shuffled.mcap");
  const auto w = write_recording(file, 9);
  ASSERT_GT(w.max_shuffle_ns, 0);
  const auto in = eval::read_recording(file, false);
  EXPECT_EQ(in.lateness_ns, w.max_shuffle_ns);
  EXPECT_EQ(in.sensor_ids.size(), 2u);
  EXPECT_EQ(in.poses.size(), 2u);
  EXPECT_EQ(in.raw + in.truth, w.events.size());
  EXPECT_TRUE(in.ticks.empty());

  eval::RecordingOptions o;
  o.methods = {"avg", "kalman"};
  const auto scored = eval::score_recording(file, o, false);
  auto eo = eval::offline_options(o, in);
  const auto direct = eval::evaluate(w.poses, w.events, eo);
  ASSERT_EQ(scored.result.streams.size(), direct.streams.size());
  for (std::size_t i = 0; i < direct.streams.size(); ++i) {
    SCOPED_TRACE(direct.streams[i].name);
    EXPECT_EQ(scored.result.streams[i].name, direct.streams[i].name);
    EXPECT_EQ(scored.result.streams[i].with_output, direct.streams[i].with_output);
    EXPECT_DOUBLE_EQ(scored.result.streams[i].accuracy.mean_error_cm(), direct.streams[i].accuracy.mean_error_cm());
  }
  EXPECT_TRUE(scored.summary["has_truth"].get<bool>());
  EXPECT_EQ(scored.summary["streams"].size(), direct.streams.size());
  std::filesystem::remove(file);
}

TEST(EvalRecording, FusedIntoACopyWithEveryMessageKept) {
  const auto file = temp("skelgraph_eval_recording_in.mcap");
  const auto out = temp("skelgraph_eval_recording_fused.mcap");
  write_recording(file, 5);
  eval::RecordingOptions o;
  o.methods = {"kalman"};
  const auto j = eval::fuse_recording(file, out, o);
  std::map<std::string, std::uint64_t> count_in, count_out;
  std::uint64_t last = 0;
  bool fused_in_order = true;
  mcap::Reader(file).for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message&) { ++count_in[ch.topic]; });
  mcap::Reader(out).for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
    ++count_out[ch.topic];
    if (ch.topic == "skelgraph/skeleton/fused") {
      fused_in_order = fused_in_order && m.log_time >= last;
      last = m.log_time;
    }
  });
  EXPECT_EQ(count_out["skelgraph/skeleton/raw"], count_in["skelgraph/skeleton/raw"]);
  EXPECT_EQ(count_out["skelgraph/skeleton/truth"], count_in["skelgraph/skeleton/truth"]);
  EXPECT_EQ(count_out["skelgraph/calibration"], 2u);
  EXPECT_EQ(count_out["skelgraph/skeleton/fused"], j["fused"].get<std::uint64_t>());
  EXPECT_GT(j["fused"].get<std::uint64_t>(), 150u);  // 6 s at 30 Hz, one person
  EXPECT_EQ(j["copied"].get<std::uint64_t>(), count_in["skelgraph/skeleton/raw"] + count_in["skelgraph/skeleton/truth"] + 2);
  EXPECT_TRUE(fused_in_order);
  // The copy scores its own recorded fusion as "live fused".
  const auto again = eval::read_recording(out, false);
  EXPECT_EQ(again.fused, j["fused"].get<std::uint64_t>());
  EXPECT_EQ(again.recorded_ids, (std::vector<std::string>{"fused"}));
  std::filesystem::remove(file);
  std::filesystem::remove(out);
}

TEST(EvalRecording, WhatCannotBeScoredSaysWhy) {
  const auto file = temp("skelgraph_eval_recording_no_poses.mcap");
  write_recording(file, 1, false);
  try {
    eval::read_recording(file, false);
    FAIL() << "no error";
  } catch (const eval::RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("on skelgraph/calibration (calibrate it"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(eval::read_recording(file, true));  // --shared-frame
  EXPECT_THROW(eval::read_recording(temp("skelgraph_no_such_file.mcap"), false), eval::RecordingError);
  EXPECT_THROW(eval::offline_options({"median"}, 0, 100), eval::RecordingError);
  std::filesystem::remove(file);
}
