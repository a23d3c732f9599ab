// The calibration component: the poses of a calibration file go out on
// skelgraph/calibration, stamped by the component's clock, and reach a reader
// that joins afterwards (transient-local: fusion started later still gets
// them); a bad file stops the graph's start naming the file and line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "../support/test_support.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

TEST(CalibrationComponent, PublishesAFilesPosesToReadersThatJoinLater) {
  const auto path = (std::filesystem::path(::testing::TempDir()) / "calibration_component.yaml").string();
  calib::CalibFile file;
  file.frame_id = "world";
  for (int i = 1; i <= 3; ++i) {
    skeleton::SensorPose p;
    p.sensor_id = "sensor" + std::to_string(i);
    p.pose = Eigen::Translation3d(0.5 * i, 1.2, -0.25 * i) * Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitY());
    p.method = i == 1 ? "ground_truth" : "skeleton";
    p.rms_residual_m = 0.01 * i;
    file.sensors.push_back(p);
  }
  calib::write_calib_file(path, file);

  const std::int64_t t0 = 12'000'000'000'000;
  auto clock = std::make_shared<FakeClock>(t0);
  auto config = test::test_config();
  config.clock = clock;
  const auto registry = builtin_registry();
  Graph graph(registry, config, 100ms);
  graph.add("calibration", "calibration",
            registry.find("calibration")->info.params.resolve({{"file", path, "test"}}, "calibration"));
  graph.start();
  // The reader joins after the poses went out.
  ASSERT_TRUE(test::wait_endpoint_count(graph.context("calibration"), test::Endpoint::Output, topics::kCalibration.name, 3));
  Context late("late_fusion", config);
  test::Collector<skeleton::SensorPose> got;
  Subscription<msg::SensorPose> sub(late, topics::kCalibration,
                                    [&](const msg::SensorPose& m, const SampleMeta&) { got.add(skeleton::from_msg(m)); });
  late.executor().start();
  ASSERT_TRUE(got.wait_count(3, 10s)) << got.items().size() << " of 3 poses";
  std::map<std::string, skeleton::SensorPose> by_id;
  for (const auto& p : got.items()) by_id[p.sensor_id] = p;
  ASSERT_EQ(by_id.size(), 3u);
  for (const auto& want : file.sensors) {
    SCOPED_TRACE(want.sensor_id);
    const auto& p = by_id.at(want.sensor_id);
    EXPECT_EQ(p.frame_id, "world");
    EXPECT_EQ(p.method, want.method);
    EXPECT_EQ(p.stamp_ns, t0);  // the component's clock
    EXPECT_NEAR(p.rms_residual_m, want.rms_residual_m, 1e-9);
    EXPECT_LT((p.pose.translation() - want.pose.translation()).norm(), 1e-6);
    EXPECT_LT(Eigen::AngleAxisd(p.pose.linear().transpose() * want.pose.linear()).angle(), 1e-6);
  }
  graph.stop();
  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].details["published"], 3);
  EXPECT_EQ(reports[0].state, "OK");
}

TEST(CalibrationComponent, ABadFileStopsTheStartNamingFileAndLine) {
  const auto path = (std::filesystem::path(::testing::TempDir()) / "calibration_bad.yaml").string();
  std::ofstream(path) << "version: 1\nframe_id: world\nsensors:\n  - id: sensor1\n    translation: [0, 1.2, x]\n"
                         "    rotation_xyzw: [0, 0, 0, 1]\n";
  const auto registry = builtin_registry();
  Graph graph(registry, test::test_config());
  try {
    graph.add("calibration", "calibration",
              registry.find("calibration")->info.params.resolve({{"file", path, "test"}}, "calibration"));
    FAIL() << "a bad calibration file was taken";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ":5"), std::string::npos) << what;
    EXPECT_NE(what.find("calibration"), std::string::npos) << what;  // the component's name
  }
  try {
    graph.add("nofile", "calibration", registry.find("calibration")->info.params.resolve({}, "nofile"));
    FAIL() << "a calibration component without a file was made";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("parameter 'file' is required"), std::string::npos) << e.what();
  }
}
