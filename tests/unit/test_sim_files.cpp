// A simulation written to files: sim export's CSVs (every truth and sensor
// frame, read back by the playback reader), the hand-at-tool recording (the
// tool where the hand is, within the contact distance and the robot's error),
// and synthetic board views with their truth (poses, markers, tool poses) and
// the refusal of a robot that cannot show a sensor the board.
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"

#include <filesystem>

#include "skelgraph/calib/sim_boards.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/info.hpp"
#include "skelgraph/robot/arm.hpp"
#include "skelgraph/sim/sim_component.hpp"
#include "skelgraph/sim/sim_files.hpp"

using namespace skelgraph;
namespace fs = std::filesystem;

namespace {
sim::SimConfig short_walk() {
  sim::SimConfig cfg;
  cfg.scenario.name = "walk";
  return cfg;
}
}  // namespace

TEST(SimFiles, ExportWritesEveryFrameOfTheTruthAndEachSensor) {
  const auto dir = test::fresh_path("sim_export");
  int calls = 0;
  double last_done = 0, total = 0;
  const auto s = sim::export_simulation(short_walk(), dir.string(), [&](double done, double all) {
    ++calls;
    last_done = done;
    total = all;
  });
  EXPECT_GT(s.duration_s, 5.0);
  EXPECT_GE(calls, 2);
  EXPECT_EQ(last_done, total);
  const auto truth = playback::read_recording(playback::Format::Generic, (dir / "truth.csv").string());
  EXPECT_EQ(static_cast<std::size_t>(s.files["truth.csv"]), truth.frames.size());
  EXPECT_EQ(truth.metadata.at("scenario"), "walk");
  for (const auto* sensor : {"raw_sensor1.csv", "raw_sensor2.csv"}) {
    const auto raw = playback::read_recording(playback::Format::Generic, (dir / sensor).string());
    EXPECT_EQ(static_cast<std::size_t>(s.files[sensor]), raw.frames.size()) << sensor;
    EXPECT_GT(raw.frames.size(), 100u) << sensor;
  }
  EXPECT_TRUE(fs::exists(dir / "truth.bvh"));  // one person from start to end
  EXPECT_TRUE(fs::exists(dir / "phases.csv"));
}

TEST(SimFiles, HandAtToolRecordsTheToolWhereTheHandIs) {
  const auto out = (test::fresh_path("hand_at_tool") += ".mcap").string();
  auto cfg = short_walk();
  cfg.scenario.name = "arms";
  const auto s = sim::write_hand_at_tool(cfg, out, {});
  EXPECT_GT(s.robot_states, 100u);
  EXPECT_GT(s.raw_skeletons, s.robot_states);  // two sensors, truth rate
  const auto info = recording::recording_info(out);
  ASSERT_TRUE(info["valid"].get<bool>()) << info["problem"];
  std::map<std::string, std::size_t> counts;
  for (const auto& t : info["topics"]) counts[t["topic"]] = t["count"];
  EXPECT_EQ(counts["skelgraph/robot/state"], s.robot_states);
  EXPECT_EQ(counts["skelgraph/skeleton/raw"], s.raw_skeletons);
  EXPECT_EQ(counts["skelgraph/calibration"], cfg.sensors.size());
}

TEST(SimBoards, ViewsEverySensorSeesWithTheirTruth) {
  const auto dir = test::fresh_path("sim_boards");
  const auto cfg = short_walk();
  calib::SimBoardsOptions o;
  o.dir = dir.string();
  o.board = calib::Board::parse("9x6", 0.08);
  o.views = 3;
  o.intrinsics_views = 3;
  const auto s = calib::write_sim_boards(cfg, o);
  EXPECT_EQ(s.views, 3u);
  EXPECT_EQ(s.images, cfg.sensors.size() * (3 * 2 + 3));
  for (const auto& sensor : cfg.sensors) {
    EXPECT_TRUE(fs::exists(dir / sensor.id / "002_color.png"));
    EXPECT_TRUE(fs::exists(dir / sensor.id / "002_depth.png"));
    EXPECT_TRUE(fs::exists(dir / sensor.id / "intrinsics" / "002_color.png"));
  }
  const auto truth = calib::read_calib_file((dir / "truth.yaml").string());
  ASSERT_EQ(truth.sensors.size(), cfg.sensors.size());
  for (std::size_t i = 0; i < cfg.sensors.size(); ++i) {
    EXPECT_LT((truth.sensors[i].pose.translation() - cfg.sensors[i].position).norm(), 1e-6);
    EXPECT_EQ(truth.sensors[i].method, "ground_truth");
  }
  const auto markers = calib::read_board_markers((dir / "markers.yaml").string());
  EXPECT_EQ(markers.in_world.size(), 3u);
  EXPECT_EQ(markers.in_board.size(), 5u);
}

TEST(SimBoards, TheBoardOnARobotsToolAndARobotOutOfReach) {
  const auto dir = test::fresh_path("sim_robot_boards");
  const auto cfg = short_walk();
  calib::RobotBoardsOptions o;
  o.boards.dir = dir.string();
  o.boards.board = calib::Board::parse("9x6", 0.08);
  o.boards.views = 3;
  o.world_from_base = robot::base_pose(0.8, 0, 1.0, 180);
  o.base_text = "0.8,0,1.0,180";
  const auto s = calib::write_sim_robot_boards(cfg, o);
  EXPECT_EQ(s.robot_poses, 3 * cfg.sensors.size());
  for (const auto& sensor : cfg.sensors) EXPECT_GE(s.views.at(sensor.id), 3u) << sensor.id;
  const auto tool = calib::read_tool_poses((dir / "tool_poses.yaml").string());
  EXPECT_EQ(tool.robot, "UR5e");
  EXPECT_EQ(tool.base_from_tool.size(), s.robot_poses);
  // A robot 9 m away shows no sensor the board: refused, naming the sensor.
  o.world_from_base = robot::base_pose(9, 0, 9, 0);
  o.base_text = "9,0,9,0";
  try {
    calib::write_sim_robot_boards(cfg, o);
    FAIL() << "a robot out of reach was taken";
  } catch (const calib::CalibError& e) {
    EXPECT_NE(std::string(e.what()).find("sensor1: the robot at 9,0,9,0"), std::string::npos) << e.what();
  }
}

TEST(SimParams, AssignmentsThenExtrasMakeACheckedConfiguration) {
  const auto cfg = sim::sim_config_from_assignments({"sensor_count=3", "seed=7"}, "test", {{"scenario", "arms", "test"}});
  EXPECT_EQ(cfg.sensors.size(), 3u);
  EXPECT_EQ(cfg.scenario.seed, 7u);
  EXPECT_EQ(cfg.scenario.name, "arms");
  EXPECT_THROW(sim::sim_config_from_assignments({"sensor_count"}, "test"), runtime::ParamError);  // no '='
  EXPECT_THROW(sim::sim_config_from_assignments({"no_such=1"}, "test"), runtime::ParamError);
  try {
    sim::sim_config_from_assignments({"scenario=dance"}, "sim export");
    FAIL() << "an unknown scenario was accepted";
  } catch (const runtime::ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("dance"), std::string::npos) << e.what();
  }
}
