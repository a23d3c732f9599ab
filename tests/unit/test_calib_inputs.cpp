// What the calibrations read (calib/inputs.hpp) and the simulated cell's
// check against the truth (calib/sim_check.hpp): skeletons per sensor on the
// recorder's clock with the recorded poses, hands beside the robot's tool in
// time order, clear errors naming the file, and a simulated pair placed near
// its true pose.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/calib/inputs.hpp"
#include "skelgraph/calib/sim_check.hpp"
#include "skelgraph/calib/skeleton_run.hpp"
#include "skelgraph/msg/messages.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;

namespace {

skeleton::Skeleton person(const std::string& sensor, std::uint32_t id, double x) {
  skeleton::Skeleton s;
  s.sensor_id = sensor;
  s.person_id = id;
  for (std::size_t k = 0; k < skeleton::kJointCount; ++k) {
    auto& j = s[skeleton::joint_at(k)];
    j.position = Eigen::Vector3d(x, 1.0 + 0.05 * static_cast<double>(k), 2.0);
    j.confidence = 1.0f;
  }
  return s;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("skelgraph_test_calib_inputs_" + name)).string();
}

}  // namespace

TEST(CalibInputs, SkeletonsPerSensorOnTheRecordersClockWithTheRecordedPoses) {
  const auto path = temp_path("skeletons.mcap");
  {
    recording::BagWriter bag(path);
    skeleton::SensorPose p;
    p.sensor_id = "sensor2";
    p.pose = Eigen::Translation3d(1, 0, 0) * Eigen::Isometry3d::Identity();
    bag.write("skelgraph/calibration", skeleton::to_msg(p), 5, 5);
    skeleton::SensorPose elsewhere = p;  // a pose in another frame is not the world's: left out
    elsewhere.sensor_id = "sensor3";
    elsewhere.frame_id = "robot1";
    bag.write("skelgraph/calibration", skeleton::to_msg(elsewhere), 5, 5);
    for (int i = 0; i < 3; ++i) {
      auto a = person("sensor1", 1, 0.1 * i), b = person("sensor2", 4, 0.2 * i);
      a.stamp_ns = 999;  // the sensors' own stamps are not the recorder's clock
      b.stamp_ns = 999;
      bag.write("skelgraph/skeleton/raw", skeleton::to_msg(a), static_cast<std::uint64_t>(100 + 10 * i), 0);
      bag.write("skelgraph/skeleton/raw", skeleton::to_msg(b), static_cast<std::uint64_t>(105 + 10 * i), 0);
    }
  }
  const auto in = calib::read_skeleton_input(path, "", false);
  ASSERT_EQ(in.by_sensor.size(), 2u);
  ASSERT_EQ(in.by_sensor.at("sensor1").size(), 3u);
  EXPECT_EQ(in.by_sensor.at("sensor1")[2].t_ns, 120);
  EXPECT_EQ(in.by_sensor.at("sensor2")[1].t_ns, 115);
  EXPECT_NEAR(in.by_sensor.at("sensor2")[2].skeleton[skeleton::JointId::Head].position.x(), 0.4, 1e-12);
  ASSERT_EQ(in.poses.size(), 1u);
  EXPECT_TRUE(in.poses.at("sensor2").isApprox(Eigen::Isometry3d(Eigen::Translation3d(1, 0, 0))));
  EXPECT_TRUE(in.skipped_note.empty());
  std::filesystem::remove(path);
  try {
    calib::read_skeleton_input(path, "", false);
    FAIL() << "a missing file was read";
  } catch (const calib::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(calib::read_skeleton_input(path, "no-such-format", false), calib::InputError);
}

TEST(CalibInputs, HandsBesideTheToolInTimeOrderAndWhatIsMissingNamed) {
  const auto path = temp_path("hands.mcap");
  {
    recording::BagWriter bag(path);
    // Written out of log-time order: read back sorted.
    for (int i : {2, 0, 1}) {
      msg::RobotState st;
      st.tool_position().x(0.1 * i);
      bag.write("skelgraph/robot/state", st, static_cast<std::uint64_t>(1000 + 100 * i), 0);
      auto s = person("sensor1", 7, 0.3 * i);
      s[skeleton::JointId::LeftHand].confidence = 0.5f * static_cast<float>(i % 2);  // inferred at i = 0 and 2: left out
      bag.write("skelgraph/skeleton/raw", skeleton::to_msg(s), static_cast<std::uint64_t>(1010 + 100 * i), 0);
    }
  }
  const auto in = calib::read_hand_input(path, {skeleton::JointId::RightHand, skeleton::JointId::LeftHand});
  EXPECT_EQ(in.states, 3u);
  ASSERT_EQ(in.tool.size(), 3u);
  EXPECT_EQ(in.tool[0].t_ns, 1000);
  EXPECT_NEAR(in.tool[2].p.x(), 0.2, 1e-12);
  const auto& people = in.hands.at("sensor1");
  ASSERT_EQ(people.at({7, 0}).size(), 3u);  // the right hand every time
  EXPECT_EQ(people.at({7, 0})[1].t_ns, 1110);
  ASSERT_EQ(people.at({7, 1}).size(), 1u);  // the left only where it was tracked
  EXPECT_EQ(people.at({7, 1})[0].t_ns, 1110);
  // A recording without the robot's state says so.
  const auto no_robot = temp_path("no_robot.mcap");
  {
    recording::BagWriter bag(no_robot);
    bag.write("skelgraph/skeleton/raw", skeleton::to_msg(person("sensor1", 1, 0)), 10, 0);
  }
  try {
    calib::read_hand_input(no_robot, {skeleton::JointId::RightHand});
    FAIL() << "a recording without robot states was read";
  } catch (const calib::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no skelgraph/robot/state"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
  std::filesystem::remove(no_robot);
}

TEST(CalibSimCheck, ASimulatedPairIsPlacedNearItsTruthAndComparedWithThePairAlone) {
  sim::SimConfig cfg;
  cfg.scenario.name = "walk";
  cfg.scenario.repeats = 1000;
  const auto check = calib::check_cell_calibration(cfg, 30.0, true);
  ASSERT_TRUE(check.error.empty()) << check.error;
  EXPECT_EQ(check.reference, cfg.sensors.front().id);
  ASSERT_EQ(check.sensors.size(), cfg.sensors.size() - 1);
  const auto& s = check.sensors.front();
  EXPECT_TRUE(s.placed);
  EXPECT_GT(s.frames, 500u);
  EXPECT_LT(s.error.deg, 2.0);
  EXPECT_LT(s.error.cm, 5.0);
  ASSERT_TRUE(s.pair && s.pair->solved);
  ASSERT_TRUE(s.floor);
  EXPECT_LE(s.floor->median_m, s.floor->start_median_m);  // the search never ends above where it started
  EXPECT_TRUE(check.within(2.0, 5.0));
  EXPECT_FALSE(check.within(s.error.deg / 2, 5.0));
  const auto e = calib::pose_error(Eigen::Isometry3d(Eigen::Translation3d(0.03, 0.04, 0)), Eigen::Isometry3d::Identity());
  EXPECT_NEAR(e.cm, 5.0, 1e-9);
  EXPECT_NEAR(e.deg, 0.0, 1e-9);
}

// bag import-bvh --transform: a rotation and translation, or a calibration
// file's sensor; what is wrong named with the file.
TEST(CalibFile, ATransformFromItsOwnFileOrACalibrationFile) {
  const auto path = temp_path("transform.yaml");
  const auto write = [&](const std::string& text) {
    std::ofstream(path) << text;
  };
  write("rotation: [0, -1, 0, 1, 0, 0, 0, 0, 1]\ntranslation: [1, 2, 3]\n");
  const auto t = calib::read_transform_file(path, "mocap");
  EXPECT_TRUE(t.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE((t.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  const auto message = [&](const std::string& text) {
    write(text);
    try {
      calib::read_transform_file(path, "mocap");
    } catch (const calib::CalibFileError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("rotation: [2, 0, 0, 0, 1, 0, 0, 0, 1]\ntranslation: [0, 0, 0]\n").find("is not a rotation"), std::string::npos);
  EXPECT_NE(message("rotation: [1, 0, 0]\n").find("expected rotation"), std::string::npos);
  EXPECT_NE(message("rotation: [a, 0, 0, 0, 1, 0, 0, 0, 1]\ntranslation: [0, 0, 0]\n").find(path), std::string::npos);
  // A calibration file: its sensor "mocap" is the pose.
  calib::CalibFile f;
  skeleton::SensorPose p;
  p.sensor_id = "mocap";
  p.pose = Eigen::Translation3d(0, 0, 4) * Eigen::Isometry3d::Identity();
  f.sensors.push_back(p);
  calib::write_calib_file(path, f);
  EXPECT_TRUE(calib::read_transform_file(path, "mocap").translation().isApprox(Eigen::Vector3d(0, 0, 4)));
  try {
    calib::read_transform_file(path, "vicon");
    FAIL() << "a sensor the file does not have was found";
  } catch (const calib::CalibFileError& e) {
    EXPECT_NE(std::string(e.what()).find("no sensor 'vicon'"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

// calib skeleton's report (calib/skeleton_run.hpp): a simulated pair placed
// near its truth and accepted, the held-out half checked; three sensors make
// the whole cell's report; a sensor the input lacks is named with the input.
TEST(CalibSkeletonRun, APairAndACellFromSimulatedSkeletons) {
  const auto input = [](int sensors) {
    sim::SimConfig cfg;
    cfg.scenario.name = "walk";
    cfg.scenario.repeats = 2;
    cfg.sensors = sim::default_sensors(sensors);
    sim::Simulation sim(cfg);
    calib::SkeletonInput in;
    for (auto& e : sim.advance(sim.duration())) {
      if (e.kind == sim::SimEvent::Kind::Raw) in.by_sensor[e.skeleton.sensor_id].push_back({e.skeleton.stamp_ns, e.skeleton});
    }
    return std::pair{in, cfg};
  };
  auto [pair_in, pair_cfg] = input(2);
  calib::SkeletonRun run;
  run.ref = "sensor1";
  run.holdout = true;
  std::vector<skeleton::SensorPose> poses;
  const auto j = calib::calibrate_skeletons("walk", pair_in, run, &poses);
  EXPECT_EQ(j["other"], "sensor2");
  EXPECT_TRUE(j["improved"].get<bool>()) << j["verdict"];
  EXPECT_LT(j["held_out_median_distance_cm"]["after"].get<double>(), j["held_out_median_distance_cm"]["before"].get<double>());
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].method, "skeleton");
  const Eigen::Isometry3d truth = pair_cfg.sensors[0].world_from_sensor().inverse() * pair_cfg.sensors[1].world_from_sensor();
  const auto err = calib::pose_error(poses[0].pose, truth);
  EXPECT_LT(err.cm, 5.0);
  EXPECT_LT(err.deg, 2.0);
  EXPECT_EQ(calib::pose_json(truth)["translation_m"].size(), 3u);
  EXPECT_EQ(calib::cm(0.12345), 12.3);

  auto [cell_in, cell_cfg] = input(3);
  poses.clear();
  run.holdout = false;
  const auto c = calib::calibrate_skeletons("cell", cell_in, run, &poses);
  EXPECT_EQ(c["mode"], "cell");
  EXPECT_EQ(c["sensors"].size(), 2u);
  EXPECT_EQ(c["unplaced"], 0);
  EXPECT_EQ(poses.size(), 2u);

  run.ref = "sensor9";
  try {
    calib::calibrate_skeletons("walk.mcap", pair_in, run, nullptr);
    FAIL() << "a reference the input lacks was taken";
  } catch (const calib::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("walk.mcap: no skeletons of reference sensor 'sensor9'"), std::string::npos) << e.what();
  }
}
