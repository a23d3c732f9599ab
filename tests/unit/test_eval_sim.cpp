// A simulated scenario scored (eval sim's run): every single sensor and the
// fusion methods asked for, on the same ticks; every stream carries its
// fuser's counts in the JSON; the same seed gives the same figures; a source
// or depth size it does not know is refused before anything runs.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

#include "skelgraph/eval/recording.hpp"
#include "skelgraph/eval/sim_run.hpp"

using namespace skelgraph;

TEST(EvalSim, EveryStreamIsScoredOnTheSameTicks) {
  sim::SimConfig cfg;
  cfg.scenario.name = "walk";
  const auto options = eval::offline_options({"avg", "kalman"}, 0, 100);
  int said = 0;
  const auto run = eval::run_simulation(cfg, options, {}, [&](const std::string&) { ++said; });
  EXPECT_GT(said, 0);
  EXPECT_TRUE(run.depth.is_null());
  std::set<std::string> names;
  for (const auto& s : run.result.streams) {
    names.insert(s.name);
    EXPECT_EQ(s.ticks, run.result.ticks) << s.name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"sensor1", "sensor2", "avg", "kalman"}));
  const auto json = eval::streams_json(run.result);
  ASSERT_EQ(json.size(), 4u);
  for (const auto& s : json) {
    ASSERT_TRUE(s.contains("fuser")) << s["stream"];  // singles run through a fuser of their own too
    EXPECT_GT(s["fuser"]["fused"].get<int>(), 100) << s["stream"];
    EXPECT_GT(s["ticks_with_output"].get<int>(), 100) << s["stream"];
  }
  // Seeded: the same run gives the same figures.
  const auto again = eval::streams_json(eval::run_simulation(cfg, options, {}).result);
  EXPECT_EQ(again, json);
}

TEST(EvalSim, AnUnknownSourceOrDepthSizeIsRefused) {
  sim::SimConfig cfg;
  const auto options = eval::offline_options({"avg"}, 0, 100);
  EXPECT_THROW(eval::run_simulation(cfg, options, {"kinect", "320x240", 1.0}), std::invalid_argument);
  try {
    eval::run_simulation(cfg, options, {"depth", "100x100", 1.0});
    FAIL() << "a depth size it does not know was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("expected 160x120, 320x240 or 640x480"), std::string::npos) << e.what();
  }
}
