// Recordings with skelgraph's conventions: every real data-set format goes
// into an MCAP file and comes back out exactly (import/export round trip).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>

#include <unistd.h>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/recording/info.hpp"
#include "skelgraph/recording/merge.hpp"
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

// bag merge as a library: two hosts' recordings onto the master's clock, the
// sample both recorded kept once, a host's repeats kept, ticks associated,
// a file that is not a host's recording refused.
TEST(Merge, TwoHostsOntoTheMastersClockInOrder) {
  const auto dir = fs::temp_directory_path() / ("skelgraph_merge_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto skel = [](const std::string& sensor, std::uint64_t frame, std::int64_t stamp) {
    msg::Skeleton s;
    s.sensor_id(sensor);
    s.person_id(1);
    s.frame_number(frame);
    s.stamp_ns(stamp);
    return s;
  };
  const std::uint64_t s0 = 1'000'000'000'000;
  {
    // Host "master": ticks every 100 ms; sensorA's frames; one sample host "b" recorded as well.
    recording::BagWriter a((dir / "a.mcap").string());
    a.write_metadata("session", {{"host", "master"}});
    for (int k = 0; k < 10; ++k) {
      msg::SyncCommand tick;
      tick.kind(msg::SYNC_TICK);
      tick.session_id(7);
      tick.tick(static_cast<std::uint64_t>(k));
      tick.master_stamp_ns(static_cast<std::int64_t>(s0) + k * 100'000'000);
      a.write("skelgraph/sync", tick, s0 + k * 100'000'000ULL + 1'000, 0);
      a.write("skelgraph/skeleton/raw", skel("sensorA", static_cast<std::uint64_t>(k), 0), s0 + k * 100'000'000ULL + 50'000'000, 0);
    }
    a.write("skelgraph/skeleton/raw", skel("shared", 1, 42), s0 + 500'000'000, 0);
    a.close();
    // Host "b": its clock 2 s ahead of the master's (its estimate recorded by the master's clock topic);
    // sensorB's frames, the shared sample (seen 1 ms later), and a repeat of its own.
    recording::BagWriter b((dir / "b.mcap").string());
    b.write_metadata("session", {{"host", "b"}});
    msg::ClockOffset c;
    c.host("b");
    c.offset_ns(2'000'000'000);
    c.stamp_ns(static_cast<std::int64_t>(s0));
    b.write("skelgraph/sync/clock", c, s0 + 2'000'000'000ULL, 0);
    for (int k = 0; k < 10; ++k)
      b.write("skelgraph/skeleton/raw", skel("sensorB", static_cast<std::uint64_t>(k), 0), s0 + 2'000'000'000ULL + k * 100'000'000ULL + 60'000'000, 0);
    b.write("skelgraph/skeleton/raw", skel("shared", 1, 42), s0 + 2'000'000'000ULL + 501'000'000, 0);
    b.write("skelgraph/skeleton/raw", skel("sensorB", 9, 0), s0 + 2'000'000'000ULL + 960'000'000, 0);  // a repeat of its own
    b.close();
    recording::BagWriter none((dir / "none.mcap").string());
    none.write("skelgraph/skeleton/raw", skel("x", 1, 0), s0, 0);
    none.close();
  }
  recording::MergeOptions o;
  o.queue_bytes = 64;  // the reader threads hand over a message or two at a time
  const auto r = recording::merge_recordings({(dir / "a.mcap").string(), (dir / "b.mcap").string()},
                                             (dir / "out.mcap").string(), o);
  EXPECT_EQ(r.duplicates_dropped, 1u);
  EXPECT_EQ(r.tick_records, 10u);
  ASSERT_EQ(r.inputs.size(), 2u);
  EXPECT_TRUE(r.inputs[1].estimated);
  EXPECT_EQ(r.inputs[1].offset_ns, 2e9);
  EXPECT_EQ(r.out_of_order, 0u);
  // Out: every message on the master's clock, in order; sensorB 10 ms after sensorA each tick.
  std::vector<std::pair<std::uint64_t, std::string>> out;
  std::uint64_t shared = 0, b9 = 0;
  mcap::Reader(( dir / "out.mcap").string()).for_each_message([&](const mcap::Channel& ch, const mcap::Schema*, const mcap::Message& m) {
    std::string what = ch.topic;
    if (ch.topic == "skelgraph/skeleton/raw") {
      const auto s = msg::from_cdr<msg::Skeleton>(m.data.data(), m.data.size());
      what += " " + s.sensor_id().to_string();
      if (s.sensor_id().to_string() == "shared") ++shared;
      if (s.sensor_id().to_string() == "sensorB" && s.frame_number() == 9) ++b9;
    }
    out.emplace_back(m.log_time, what);
  });
  EXPECT_EQ(out.size(), r.messages);
  EXPECT_TRUE(std::is_sorted(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first < y.first; }));
  EXPECT_EQ(shared, 1u);
  EXPECT_EQ(b9, 2u);  // a host's own repeat is kept
  const auto b0 = std::find(out.begin(), out.end(), std::make_pair(s0 + 60'000'000, std::string("skelgraph/skeleton/raw sensorB")));
  EXPECT_NE(b0, out.end()) << "sensorB's first frame not at its corrected time";
  // A file without a host's session metadata: refused, naming it.
  try {
    recording::merge_recordings({(dir / "a.mcap").string(), (dir / "none.mcap").string()}, (dir / "bad.mcap").string());
    ADD_FAILURE() << "merged a file without a host";
  } catch (const recording::MergeError& e) {
    EXPECT_NE(std::string(e.what()).find("none.mcap"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// What `bag info` reports (recording/info.hpp): ticks and sessions from the
// sync topic, who acknowledged them, skeletons per sensor, counts per topic;
// a file cut short is not valid and says where.
TEST(RecordingInfo, TicksAcksSkeletonsAndADamagedFile) {
  const auto dir = fs::temp_directory_path() / ("skelgraph_info_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto path = (dir / "r.mcap").string();
  {
    recording::BagWriter w(path);
    w.write_metadata("session", {{"host", "h1"}});
    for (int k = 0; k < 5; ++k) {
      msg::SyncCommand tick;
      tick.kind(msg::SYNC_TICK);
      tick.session_id(3);
      tick.tick(static_cast<std::uint64_t>(k));
      w.write("skelgraph/sync", tick, 1000 + 100 * static_cast<std::uint64_t>(k), 0);
      msg::SyncAck ack;
      ack.session_id(3);
      ack.tick(static_cast<std::uint64_t>(k));
      ack.host("h1");
      if (k < 4) w.write("skelgraph/sync_ack", ack, 1010 + 100 * static_cast<std::uint64_t>(k), 0);
      msg::Skeleton s;
      s.sensor_id(k % 2 ? "s2" : "s1");
      w.write("skelgraph/skeleton/raw", s, 1050 + 100 * static_cast<std::uint64_t>(k), 0);
    }
    w.close();
  }
  const auto d = recording::recording_info(path);
  EXPECT_TRUE(d["valid"].get<bool>()) << d["problem"];
  EXPECT_EQ(d["ticks"], 5);
  EXPECT_EQ(d["sessions"], nlohmann::json::array({3}));
  EXPECT_EQ(d["messages"], 14);
  EXPECT_EQ(d["skeletons_per_sensor"]["skelgraph/skeleton/raw s1"], 3);
  EXPECT_EQ(d["skeletons_per_sensor"]["skelgraph/skeleton/raw s2"], 2);
  EXPECT_FALSE(d["ticks_acked_by_host"].empty()) << d["ticks_acked_by_host"];
  std::map<std::string, int> counts;
  for (const auto& t : d["topics"]) counts[t["topic"].get<std::string>()] = t["count"].get<int>();
  EXPECT_EQ(counts["skelgraph/sync_ack"], 4);
  // Cut short in the middle of its data: read what is there, say why it is not valid.
  const auto cut = (dir / "cut.mcap").string();
  fs::copy_file(path, cut);
  fs::resize_file(cut, fs::file_size(path) / 2);
  try {
    const auto c = recording::recording_info(cut);
    EXPECT_FALSE(c["valid"].get<bool>());
    EXPECT_FALSE(c["problem"].get<std::string>().empty());
  } catch (const mcap::McapError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.mcap"), std::string::npos) << e.what();  // or unreadable, named
  }
  fs::remove_all(dir);
}
