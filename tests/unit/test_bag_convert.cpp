// Recordings to and from other files: data-set skeletons imported and exported
// again unchanged (generic CSV), the numeric columns, a negative stamp
// refused naming the file, and motion capture added to a recording as its
// truth at the recording's start.
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"

#include <filesystem>
#include <fstream>
#include <map>

#include "skelgraph/playback/bvh.hpp"
#include "skelgraph/recording/convert.hpp"
#include "skelgraph/recording/info.hpp"

using namespace skelgraph;
namespace fs = std::filesystem;

namespace {
playback::Recording walk(const std::string& sensor, std::int64_t t0, int frames) {
  playback::Recording r;
  r.format = "generic";
  for (int i = 0; i < frames; ++i) {
    skeleton::Skeleton s;
    s.sensor_id = sensor;
    s.person_id = 1;
    s.frame_id = sensor;
    s.stamp_ns = t0 + i * 33'333'333LL;
    s.frame_number = static_cast<std::uint64_t>(i);
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      s.joints[j].position = {0.01 * i, 0.1 * static_cast<double>(j), 2.0};
      s.joints[j].confidence = skeleton::kTracked;
    }
    r.frames.push_back(s);
  }
  return r;
}
std::string write_csv(const fs::path& path, const playback::Recording& r) {
  std::ofstream out(path);
  playback::write_generic_csv(r, out);
  return path.string();
}
}  // namespace

TEST(BagConvert, ImportedSkeletonsExportUnchanged) {
  const auto dir = test::fresh_path("bag_convert");
  fs::create_directories(dir);
  const auto a = write_csv(dir / "a.csv", walk("kinect_a", 1'000'000'000, 30));
  const auto b = write_csv(dir / "b.csv", walk("kinect_b", 1'010'000'000, 20));
  std::map<std::string, std::size_t> per_file;
  const auto frames = recording::import_skeletons(playback::Format::Generic, {a, b}, {}, (dir / "in.mcap").string(),
                                                  mcap::Compression::Zstd,
                                                  [&](const std::string& f, std::size_t n) { per_file[f] = n; });
  EXPECT_EQ(frames, 50u);
  EXPECT_EQ(per_file[a], 30u);
  EXPECT_EQ(per_file[b], 20u);
  const auto files = recording::export_skeletons((dir / "in.mcap").string(), recording::SkeletonCsv::Generic, (dir / "out").string());
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(fs::path(files[0].first).filename(), "raw_kinect_a.csv");
  EXPECT_EQ(files[0].second, 30u);
  const auto back = playback::read_recording(playback::Format::Generic, files[0].first);
  const auto want = walk("kinect_a", 1'000'000'000, 30);
  ASSERT_EQ(back.frames.size(), want.frames.size());
  for (std::size_t i = 0; i < want.frames.size(); ++i) {
    EXPECT_EQ(back.frames[i].stamp_ns, want.frames[i].stamp_ns);
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      EXPECT_EQ(back.frames[i].joints[j].position, want.frames[i].joints[j].position);
    }
  }
  // Numeric columns: a header and a line per frame, time from the first frame.
  const auto cols = recording::export_skeletons((dir / "in.mcap").string(), recording::SkeletonCsv::Columns, (dir / "cols").string());
  std::ifstream in(cols[1].first);
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  EXPECT_EQ(header.rfind("stamp_ns,time_s,person_id,frame_number,head_x,head_y,head_z,head_conf", 0), 0u) << header;
  EXPECT_EQ(first.rfind("1010000000,0,1,0,", 0), 0u) << first;
}

TEST(BagConvert, ANegativeStampIsRefusedNamingTheFile) {
  const auto dir = test::fresh_path("bag_convert_negative");
  fs::create_directories(dir);
  const auto f = write_csv(dir / "early.csv", walk("s", -100'000'000, 5));
  try {
    recording::import_skeletons(playback::Format::Generic, {f}, {}, (dir / "x.mcap").string(), mcap::Compression::None);
    FAIL() << "a negative stamp was recorded";
  } catch (const recording::ConvertError& e) {
    EXPECT_NE(std::string(e.what()).find(f + ": negative time stamp"), std::string::npos) << e.what();
  }
}

TEST(BagConvert, MocapIsAddedAsTheTruthAtTheRecordingsStart) {
  const auto dir = test::fresh_path("bag_convert_mocap");
  fs::create_directories(dir);
  const auto f = write_csv(dir / "a.csv", walk("kinect_a", 5'000'000'000, 30));
  recording::import_skeletons(playback::Format::Generic, {f}, {}, (dir / "rec.mcap").string(), mcap::Compression::Zstd);
  {
    std::ofstream bvh(dir / "m.bvh");
    playback::write_position_bvh(walk("mocap", 0, 10).frames, 0.01, 100.0, bvh);
  }
  recording::MocapImport m;
  m.file = (dir / "m.bvh").string();
  m.out = (dir / "with_truth.mcap").string();
  m.add_to = (dir / "rec.mcap").string();
  const auto r = recording::import_mocap(m);
  EXPECT_EQ(r.truth_frames, 10u);
  EXPECT_EQ(r.copied, 30u);
  EXPECT_NEAR(r.time_offset_s, 5.0, 1e-9);  // the recording's first message
  EXPECT_NEAR(r.span_s, 0.09, 1e-6);
  const auto info = recording::recording_info(m.out);
  EXPECT_EQ(info["skeletons_per_sensor"]["skelgraph/skeleton/raw kinect_a"], 30) << info["skeletons_per_sensor"];
  EXPECT_EQ(info["start_ns"], 5'000'000'000LL);
}
