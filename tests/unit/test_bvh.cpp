// Motion capture as ground truth: BVH parsing (hierarchy, channels, frames),
// forward kinematics with rotations, the joint mapping, units, the rigid
// transform and time; the simulator's truth written as BVH and read back; bad
// files named with file:line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "skelgraph/playback/bvh.hpp"
#include "skelgraph/sim/simulation.hpp"

using namespace skelgraph;
using namespace skelgraph::playback;
using Eigen::Vector3d;

namespace {
std::string write_file(const std::string& name, const std::string& text) {
  const auto path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}
}  // namespace

// A root with position and rotation channels and a child 10 units up: turning
// the root 90 degrees about Z puts the child 10 units along -X.
TEST(Bvh, ForwardKinematicsRotatesChildren) {
  const auto path = write_file("arm.bvh",
                               "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                               "  JOINT Spine\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
                               "    End Site\n    {\n      OFFSET 0 5 0\n    }\n  }\n}\n"
                               "MOTION\nFrames: 2\nFrame Time: 0.5\n1 2 3 0 0 0 0 0 0\n1 2 3 90 0 0 0 0 0\n");
  const auto b = read_bvh(path);
  ASSERT_EQ(b.joints.size(), 3u);  // the End Site too
  EXPECT_EQ(b.channel_count, 9u);
  EXPECT_EQ(b.frame_time_s, 0.5);
  EXPECT_TRUE(b.positions(0)[1].isApprox(Vector3d(1, 12, 3)));
  EXPECT_TRUE(b.positions(1)[1].isApprox(Vector3d(-9, 2, 3), 1e-12)) << b.positions(1)[1].transpose();
  EXPECT_TRUE(b.positions(1)[2].isApprox(Vector3d(-14, 2, 3), 1e-12));  // the End Site follows
  EXPECT_EQ(b.index_of("Spine"), 1);
  EXPECT_EQ(b.index_of("Spine_end"), -1);  // End Sites are no joints to map
}

TEST(Bvh, BadFilesNameTheLine) {
  const auto error = [](const std::string& text) {
    try {
      read_bvh(write_file("bad.bvh", text));
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n}\nMOTION\n";
  EXPECT_NE(error(head + "Frames: 1\nFrame Time: 0.1\n1 2\n").find("bad.bvh:10: 2 values; the hierarchy has 3 channels"),
            std::string::npos);
  EXPECT_NE(error(head + "Frames: 2\nFrame Time: 0.1\n1 2 3\n").find("1 frames; the header says 2"), std::string::npos);
  EXPECT_NE(error(head + "Frames: 1\nFrame Time: 0.1\n1 nan 3\n").find("expected a finite number, got 'nan'"), std::string::npos);
  EXPECT_NE(error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n}\n").find("bad.bvh:5: expected an OFFSET z"), std::string::npos);
  EXPECT_NE(error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Wrotation\n}\n").find("unknown channel 'Wrotation'"),
            std::string::npos);
  EXPECT_NE(error("BVH\n").find("bad.bvh:1: expected HIERARCHY"), std::string::npos);
}

// The simulator's truth as a BVH (cm, position channels), read back through
// the default mapping, units, a transform and a time offset: the same joints.
TEST(Bvh, SimulatorTruthRoundTrips) {
  sim::SimConfig cfg;
  cfg.scenario.name = "arms";
  cfg.scenario.seed = 3;
  cfg.sensors = {sim::default_sensors(1)[0]};
  sim::Simulation s(cfg);
  std::vector<skeleton::Skeleton> truth;
  for (double t = 0.5; t < 4.0; t += 1.0 / 30) truth.push_back(s.truth_at(t).at(0));
  std::ostringstream os;
  write_position_bvh(truth, 1.0 / 30, 100.0, os);
  const auto path = write_file("truth.bvh", os.str());
  const auto b = read_bvh(path);
  ASSERT_EQ(b.frames.size(), truth.size());
  BvhOptions o;  // cm
  o.time_offset_s = 1000.0;
  o.target_from_mocap.translation() = Vector3d(0.5, 0, -1);
  o.target_from_mocap.linear() = Eigen::AngleAxisd(0.3, Vector3d::UnitY()).toRotationMatrix();
  const auto rec = bvh_recording(path, b, o);
  ASSERT_EQ(rec.frames.size(), truth.size());
  EXPECT_EQ(rec.frames[1].stamp_ns - rec.frames[0].stamp_ns, 33'333'333);
  EXPECT_EQ(rec.frames[0].stamp_ns, 1'000'000'000'000);
  double worst = 0;
  for (std::size_t f = 0; f < truth.size(); ++f)
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j)
      worst = std::max(worst, (rec.frames[f].joints[j].position - o.target_from_mocap * truth[f].joints[j].position).norm());
  EXPECT_LT(worst, 1e-9);
  // A mapping that names a joint the file lacks is refused, naming it.
  o.joints = {{"head", "Skull"}};
  try {
    bvh_recording(path, b, o);
    ADD_FAILURE() << "an unknown joint was mapped";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("'Skull' (for head) is not a joint of this file"), std::string::npos) << e.what();
  }
  // Matched moments: a mocap clock 1 % fast, frame 0 at 50 s.
  o.joints.clear();
  const auto points = read_bvh_time_points(write_file("points.csv", "mocap_frame,time_s\n0,50\n100,53.3\n"));
  ASSERT_EQ(points.size(), 2u);
  o.time_points = points;
  const auto timed = bvh_recording(path, b, o);
  EXPECT_EQ(timed.frames[0].stamp_ns, 50'000'000'000);
  EXPECT_NEAR(static_cast<double>(timed.frames[100].stamp_ns) * 1e-9, 53.3, 1e-6);
  EXPECT_THROW(read_bvh_time_points(write_file("points2.csv", "frame,t\n")), DataError);
  // A mapping file.
  const auto m = read_bvh_mapping(write_file("map.yaml", "joints:\n  head: Head\n  torso: Spine1\n"));
  EXPECT_EQ(m.at("torso"), "Spine1");
  EXPECT_THROW(read_bvh_mapping(write_file("map2.yaml", "joints:\n  skull: Head\n")), DataError);
}
