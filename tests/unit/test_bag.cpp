// Recordings with skelgraph's conventions: every real data-set format goes
// into an MCAP file and comes back out exactly (import/export round trip).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>

#include <unistd.h>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/recording/session_recorder.hpp"
#include "skelgraph/recording/tick_frames.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;
namespace fs = std::filesystem;

namespace {
std::string data_dir() {
  if (const char* d = std::getenv("SKELGRAPH_DATA_DIR")) return d;
  const char* src = std::getenv("SKELGRAPH_SOURCE_DIR");
  return std::string(src ? src : ".") + "/../shared/data";
}

void expect_same(const skeleton::Skeleton& a, const skeleton::Skeleton& b) {
  ASSERT_EQ(a.sensor_id, b.sensor_id);
  ASSERT_EQ(a.person_id, b.person_id);
  ASSERT_EQ(a.frame_id, b.frame_id);
  ASSERT_EQ(a.stamp_ns, b.stamp_ns);
  ASSERT_EQ(a.frame_number, b.frame_number);
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    ASSERT_EQ(a.joints[j].position, b.joints[j].position);  // bit for bit
    ASSERT_EQ(a.joints[j].orientation.coeffs(), b.joints[j].orientation.coeffs());
    ASSERT_EQ(a.joints[j].confidence, b.joints[j].confidence);
    ASSERT_EQ(a.joints[j].sensor_mask, b.joints[j].sensor_mask);
  }
}
}  // namespace

TEST(SharedData, EveryFormatRoundTripsThroughMcapExactly) {
  const std::vector<std::pair<playback::Format, std::string>> files = {
      {playback::Format::KinderGator, "kinder-gator/adults/POSE-p565_01-Raise-your-hand-1469182402284.csv"},
      {playback::Format::KinectV2, "laban/Ges05_demopoint.csv"},
      {playback::Format::MultiTrack, "kinect-multitrack/Experiments_1_2_3_6/Study_1_Kinect_2_Time_12_07_07_PM.csv"},
      {playback::Format::GesturePhase, "gesture-phase/a1_raw.csv"},
  };
  for (const auto& [format, name] : files) {
    SCOPED_TRACE(name);
    const auto path = fs::path(data_dir()) / name;
    ASSERT_TRUE(fs::exists(path)) << path << " is missing: tests read ../shared/data";
    const auto rec = playback::read_recording(format, path.string());
    ASSERT_GT(rec.frames.size(), 10u);
    const auto out = (fs::temp_directory_path() / ("roundtrip_" + std::string(playback::format_name(format)) + ".mcap")).string();
    {
      mcap::WriterOptions opt;
      opt.compression = mcap::Compression::Zstd;
      opt.chunk_size = 16 * 1024;
      recording::BagWriter bag(out, opt);
      for (const auto& s : rec.frames) {
        bag.write("skelgraph/skeleton/raw", skeleton::to_msg(s), static_cast<std::uint64_t>(s.stamp_ns),
                  static_cast<std::uint64_t>(s.stamp_ns));
      }
      bag.close();
    }
    const mcap::Reader reader(out);
    EXPECT_NO_THROW(reader.validate());
    std::size_t i = 0;
    reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
      ASSERT_NE(schema, nullptr);
      EXPECT_EQ(ch.metadata.at("dds_type"), "skelgraph::msg::Skeleton");
      EXPECT_EQ(ch.metadata.at("keyed"), "true");
      ASSERT_LT(i, rec.frames.size());
      expect_same(skeleton::from_msg(msg::from_cdr<msg::Skeleton>(m.data.data(), m.data.size())), rec.frames[i]);
      EXPECT_EQ(m.log_time, static_cast<std::uint64_t>(rec.frames[i].stamp_ns));
      EXPECT_EQ(m.sequence, i);
      ++i;
    });
    EXPECT_EQ(i, rec.frames.size());
  }
}

TEST(Bag, ForeignTypesAreRecordedWithoutASchema) {
  const auto out = (fs::temp_directory_path() / "foreign.mcap").string();
  recording::BagWriter bag(out);
  bag.write_cdr("robot/joint_states", "sensor_msgs::msg::dds_::JointState_", false, std::string_view("\0\1\0\0abcd", 8), 5, 5);
  bag.close();
  const auto s = mcap::Reader(out).summary();
  ASSERT_EQ(s.channels.size(), 1u);
  EXPECT_EQ(s.channels.begin()->second.schema_id, 0);
  EXPECT_EQ(s.channels.begin()->second.metadata.at("dds_type"), "sensor_msgs::msg::dds_::JointState_");
  EXPECT_THROW(msg::from_cdr<msg::Skeleton>("\0\1\0\0ab", 6), std::runtime_error);
}

namespace {
skelgraph::msg::FrameRef frame_ref(const std::string& sensor, std::uint32_t person, std::uint64_t n, std::int64_t t) {
  skelgraph::msg::FrameRef f;
  f.topic("skelgraph/skeleton/raw");
  f.host("h");
  f.sensor_id(sensor);
  f.person_id(person);
  f.frame_number(n);
  f.log_time_ns(t);
  return f;
}
}  // namespace

TEST(TickFrames, EachTickGetsTheLatestRecentFrameOfEveryStream) {
  skelgraph::recording::TickAssociator a(100'000'000);
  a.frame(frame_ref("s1", 1, 10, 1'000'000'000));
  a.frame(frame_ref("s1", 1, 11, 1'030'000'000));  // replaces frame 10
  a.frame(frame_ref("s2", 1, 7, 1'020'000'000));
  a.frame(frame_ref("s2", 2, 3, 1'025'000'000));   // another person: its own stream
  auto t = a.tick(5, 1, 1'033'000'000, 1'033'000'000);
  EXPECT_EQ(t.session_id(), 5u);
  EXPECT_EQ(t.tick(), 1u);
  ASSERT_EQ(t.frames().size(), 3u);
  std::map<std::pair<std::string, std::uint32_t>, std::uint64_t> got;
  for (const auto& f : t.frames()) got[{f.sensor_id().to_string(), f.person_id()}] = f.frame_number();
  EXPECT_EQ(got.at({"s1", 1}), 11u);
  EXPECT_EQ(got.at({"s2", 1}), 7u);
  EXPECT_EQ(got.at({"s2", 2}), 3u);
  // s2 falls silent: 100 ms after its last frame it is no longer attached to ticks.
  a.frame(frame_ref("s1", 1, 12, 1'063'000'000));
  t = a.tick(5, 2, 1'066'000'000, 1'066'000'000);
  EXPECT_EQ(t.frames().size(), 3u);
  a.frame(frame_ref("s1", 1, 13, 1'120'000'000));
  t = a.tick(5, 3, 1'130'000'000, 1'130'000'000);
  ASSERT_EQ(t.frames().size(), 1u);
  EXPECT_EQ(t.frames()[0].frame_number(), 13u);
  // A frame received after the tick belongs to the next one, not this.
  t = a.tick(5, 4, 1'160'000'000, 1'160'000'000);
  a.frame(frame_ref("s1", 1, 14, 1'161'000'000));
  ASSERT_EQ(t.frames().size(), 1u);
  EXPECT_EQ(t.frames()[0].frame_number(), 13u);
}

TEST(SessionRecorder, ARestartedRecorderNeverOverwritesItsSessionFile) {
  const auto dir = fs::temp_directory_path() / ("skelgraph_session_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  recording::RecorderOptions o;
  o.directory = dir.string();
  o.host = "sensor1";
  std::string first;
  {
    recording::SessionRecorder a(o, "cell", 42, 1'000);
    first = a.path();
    a.record("skelgraph/sync", "skelgraph::msg::SyncCommand", false, "abcd", 2'000, 2'000);
    a.finish(3'000);
  }
  const auto size = fs::file_size(first);
  recording::SessionRecorder b(o, "cell", 42, 4'000);  // the same session again, as after a restart
  EXPECT_EQ(fs::path(first).filename(), "cell_42_sensor1.mcap");
  EXPECT_EQ(fs::path(b.path()).filename(), "cell_42_sensor1_2.mcap");
  EXPECT_EQ(fs::file_size(first), size);  // untouched
  recording::SessionRecorder c(o, "cell", 42, 5'000);
  EXPECT_EQ(fs::path(c.path()).filename(), "cell_42_sensor1_3.mcap");
  fs::remove_all(dir);
}
