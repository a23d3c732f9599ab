// Data-set readers on hand-made files (good and broken) and on the real
// recordings in ../shared/data.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "skelgraph/playback/readers.hpp"

using namespace skelgraph;
using namespace skelgraph::playback;
using skeleton::JointId;
namespace fs = std::filesystem;

namespace {

std::string write_file(const std::string& name, const std::string& text) {
  const auto path = ::testing::TempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A Kinder-Gator header and a row whose joint j sits at (j, 10 + j, 100 + j) / 100.
std::string kg_header() {
  const char* joints[] = {"HipCenter", "Spine",     "ShoulderCenter", "Head",      "ShoulderLeft",
                          "ElbowLeft", "WristLeft", "HandLeft",       "ShoulderRight", "ElbowRight",
                          "WristRight", "HandRight", "HipLeft",       "KneeLeft",  "AnkleLeft",
                          "FootLeft",  "HipRight",  "KneeRight",      "AnkleRight", "FootRight"};
  std::string h = "Timestamp,";
  for (const auto* j : joints) h += std::string(j) + "X," + j + "Y," + j + "Z,";
  return h + "User-ID,Action,\n";
}
std::string kg_row(double ms, const std::string& override_field = {}, int override_index = -1) {
  std::ostringstream os;
  os << std::setprecision(12) << ms << ",";
  for (int j = 0; j < 20; ++j) {
    for (int k = 0; k < 3; ++k) {
      const int idx = 1 + 3 * j + k;
      if (idx == override_index) {
        os << override_field << ",";
      } else {
        os << (j + 10 * k) / 100.0 << ",";
      }
    }
  }
  os << "565,Point-at-the-camera,\n";
  return os.str();
}

std::string data_dir() {
  if (const char* d = std::getenv("SKELGRAPH_DATA_DIR")) return d;
  const char* src = std::getenv("SKELGRAPH_SOURCE_DIR");
  return std::string(src ? src : ".") + "/../shared/data";
}

}  // namespace

TEST(Readers, KinderGatorMapsJointsAndKeepsLabels) {
  const auto path = write_file("POSE-p565_01-Point-at-the-camera-1469182494249.csv",
                               kg_header() + kg_row(48000000.5) + kg_row(48000033.25));
  const auto rec = read_recording(Format::KinderGator, path);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.metadata.at("action"), "Point-at-the-camera");
  EXPECT_EQ(rec.metadata.at("subject"), "565");
  const auto& s = rec.frames[1];
  EXPECT_EQ(s.sensor_id, "kinect_v1");
  // Head is Kinect v1 joint 3, the right hand joint 11, the neck ShoulderCenter (2).
  EXPECT_DOUBLE_EQ(s[JointId::Head].position.x(), 0.03);
  EXPECT_DOUBLE_EQ(s[JointId::Head].position.y(), 0.13);
  EXPECT_DOUBLE_EQ(s[JointId::RightHand].position.z(), 0.31);
  EXPECT_DOUBLE_EQ(s[JointId::Neck].position.x(), 0.02);
  EXPECT_EQ(s[JointId::LeftFoot].confidence, skeleton::kTracked);
  // ms since midnight UTC on the day of the file name's Unix time (2016-07-22).
  const std::int64_t day_ns = 1469145600000LL * 1000000LL;
  EXPECT_EQ(rec.frames[0].stamp_ns, day_ns + 48000000500000LL);
  EXPECT_EQ(rec.frames[1].stamp_ns - rec.frames[0].stamp_ns, 32750000);
  // The wrists (joints 6 and 10), the hip centre and the ankles are not
  // canonical joints: one per frame in extra_joints.
  ASSERT_EQ(rec.extra_joints.size(), 5u);
  EXPECT_TRUE(rec.extra_joints.at("left_ankle")[0].isApprox(Eigen::Vector3d(0.14, 0.24, 0.34)));
  ASSERT_EQ(rec.extra_joints.at("left_wrist").size(), 2u);
  ASSERT_EQ(rec.extra_joints.at("right_wrist").size(), 2u);
  EXPECT_TRUE(rec.extra_joints.at("left_wrist")[1].isApprox(Eigen::Vector3d(0.06, 0.16, 0.26)));
  EXPECT_TRUE(rec.extra_joints.at("right_wrist")[0].isApprox(Eigen::Vector3d(0.10, 0.20, 0.30)));
}

TEST(Readers, BadLinesNameFileLineAndExpectation) {
  auto error = [](const std::string& body, const std::string& name) {
    const auto path = write_file(name, body);
    try {
      read_recording(Format::KinderGator, path);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(kg_header() + kg_row(1) + kg_row(2, "abc", 16), "kg_a.csv")
                .find("kg_a.csv:3: column 'ElbowLeftX' expects a number, got 'abc'"),
            std::string::npos);
  EXPECT_NE(error(kg_header() + kg_row(1, "nan", 4), "kg_b.csv").find("expects a finite number, got 'nan'"),
            std::string::npos);
  EXPECT_NE(error(kg_header() + kg_row(1, "inf", 4), "kg_c.csv").find("finite"), std::string::npos);
  EXPECT_NE(error(kg_header() + "1,2,3\n", "kg_d.csv").find("kg_d.csv:2: expected 63 fields"), std::string::npos);
  EXPECT_NE(error(kg_header() + kg_row(5) + kg_row(4), "kg_e.csv").find("kg_e.csv:3: time goes backwards"),
            std::string::npos);
  EXPECT_NE(error("Time,A\n", "kg_f.csv").find("kg_f.csv:1: expected 63 fields"), std::string::npos);
  EXPECT_NE(error("", "kg_g.csv").find("empty file"), std::string::npos);
  // A header and nothing else is no recording (it used to read as one with no frames).
  EXPECT_NE(error(kg_header(), "kg_h.csv").find("kg_h.csv:1: no data rows"), std::string::npos);
  // Input quoted in a message cannot send control bytes to a terminal.
  const auto escaped = error(kg_header() + kg_row(1, "1\x1b[2J\a", 4), "kg_i.csv");
  EXPECT_NE(escaped.find("got '1\\x1b[2J\\x07'"), std::string::npos) << escaped;
  EXPECT_EQ(escaped.find('\x1b'), std::string::npos);
  try {
    read_recording(Format::KinderGator, ::testing::TempDir() + "/nope.csv");
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.csv:0: cannot open file"), std::string::npos);
  }
}

TEST(Readers, SkipPolicyKeepsGoodLinesAndReportsBadOnes) {
  const auto path = write_file("kg_skip.csv", kg_header() + kg_row(1) + kg_row(2, "x", 7) + "oops\n" + kg_row(3) +
                                                  kg_row(2) + kg_row(4) + kg_row(4));
  ReadOptions opt;
  opt.on_error = ReadOptions::OnError::Skip;
  const auto rec = read_recording(Format::KinderGator, path, opt);
  ASSERT_EQ(rec.frames.size(), 4u);  // 1, 3, 4, 4
  EXPECT_EQ(rec.extra_joints.at("left_wrist").size(), 4u);  // a skipped line leaves no wrist behind
  EXPECT_EQ(rec.extra_joints.at("right_wrist").size(), 4u);
  EXPECT_EQ(rec.report.lines, 7u);
  EXPECT_EQ(rec.report.skipped, 3u);  // bad number, short line, time backwards
  EXPECT_EQ(rec.report.repeated_stamps, 1u);
  ASSERT_EQ(rec.report.problems.size(), 3u);
  EXPECT_NE(rec.report.problems[0].find("kg_skip.csv:3:"), std::string::npos);
  EXPECT_NE(rec.report.problems[2].find("kg_skip.csv:6: time goes backwards"), std::string::npos);
  EXPECT_NE(skipped_summary(rec).find("kg_skip.csv: 3 bad lines of 7 skipped (first: "), std::string::npos) << skipped_summary(rec);
  // Every line bad: nothing is left to read, and that is an error naming the last line.
  const auto all_bad = write_file("kg_all_bad.csv", kg_header() + kg_row(1, "x", 4) + kg_row(2, "y", 5));
  try {
    read_recording(Format::KinderGator, all_bad, opt);
    ADD_FAILURE() << "a file of bad lines read as a recording";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("kg_all_bad.csv:3: no skeleton frames: every one of the 2 data rows was bad"),
              std::string::npos) << e.what();
  }
}

TEST(Readers, PrintableEscapesControlBytesOnly) {
  EXPECT_EQ(printable("a\tb\r\n\x01\x7f"), "a\\tb\\r\\n\\x01\\x7f");
  EXPECT_EQ(printable("Grüße, 東京 ~"), "Grüße, 東京 ~");
}

TEST(Readers, KinectV2TrackingStatesBecomeConfidence) {
  std::ostringstream os;
  for (int frame = 0; frame < 2; ++frame) {
    os << 97771535532LL + frame * 333333;
    for (int j = 0; j < 25; ++j) os << "," << j * 0.1 << "," << 1.0 + j * 0.01 << "," << 2.5 << "," << (j == 7 ? 1 : j == 11 ? 0 : 2);
    os << ",\r\n";  // trailing comma, CRLF
  }
  const auto path = write_file("Ges05_demopoint.csv", os.str());
  const auto rec = read_recording(Format::KinectV2, path);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.metadata.at("gesture"), "demopoint");
  const auto& s = rec.frames[0];
  EXPECT_EQ(s[JointId::LeftHand].confidence, skeleton::kInferred);  // HandLeft = 7
  EXPECT_EQ(s[JointId::RightHand].confidence, skeleton::kLost);     // HandRight = 11
  EXPECT_EQ(s[JointId::Head].confidence, skeleton::kTracked);
  EXPECT_DOUBLE_EQ(s[JointId::Neck].position.x(), 2.0);  // SpineShoulder = 20
  EXPECT_DOUBLE_EQ(s[JointId::Torso].position.x(), 0.1);  // SpineMid = 1
  EXPECT_EQ(rec.frames[1].stamp_ns - rec.frames[0].stamp_ns, 33333300);
  // Wrists (WristLeft = 6, WristRight = 10), both tracked here.
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("left_wrist")[0].x(), 0.6);
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("right_wrist")[1].y(), 1.1);

  const auto bad = write_file("v2_bad.csv", "5" + std::string(",0,0,0,3") + std::string(24 * 8, ' ') + "\n");
  EXPECT_THROW(read_recording(Format::KinectV2, bad), DataError);
  std::string state3 = "5";
  for (int j = 0; j < 25; ++j) state3 += ",0,0,1," + std::string(j == 3 ? "3" : "2");
  try {
    read_recording(Format::KinectV2, write_file("v2_state.csv", state3 + "\n"));
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("v2_state.csv:1: HeadTrackingState expects 0, 1 or 2, got 3"), std::string::npos)
        << e.what();
  }
}

TEST(Readers, GenericCsvRoundTripsEverything) {
  Recording rec;
  rec.metadata["action"] = "point";
  rec.metadata["subject"] = "s1";
  rec.metadata["sensor_pose"] = "2.0,1.2,0.0 yaw 270";  // commas in a value survive
  for (int i = 0; i < 3; ++i) {
    skeleton::Skeleton s;
    s.sensor_id = "kinect_" + std::to_string(i % 2);
    s.person_id = static_cast<std::uint32_t>(i);
    s.frame_id = "world";
    s.stamp_ns = 1'000'000'000LL + i * 33'333'333LL;
    s.frame_number = static_cast<std::uint64_t>(10 + i);
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      s.joints[j].position = {0.1 * j + 1e-9 * i, -0.2 * j, 2.0 + 1.0 / 3.0};
      s.joints[j].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * j, Eigen::Vector3d::UnitY()));
      s.joints[j].confidence = j % 3 == 0 ? 0.5f : 1.0f;
    }
    rec.frames.push_back(s);
  }
  std::ostringstream out;
  write_generic_csv(rec, out);
  const auto path = write_file("generic.csv", out.str());
  const auto back = read_recording(Format::Generic, path);
  EXPECT_EQ(back.metadata, rec.metadata);
  ASSERT_EQ(back.frames.size(), rec.frames.size());
  for (std::size_t i = 0; i < rec.frames.size(); ++i) {
    const auto& a = rec.frames[i];
    const auto& b = back.frames[i];
    EXPECT_EQ(a.sensor_id, b.sensor_id);
    EXPECT_EQ(a.person_id, b.person_id);
    EXPECT_EQ(a.frame_id, b.frame_id);
    EXPECT_EQ(a.stamp_ns, b.stamp_ns);
    EXPECT_EQ(a.frame_number, b.frame_number);
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      EXPECT_EQ(a.joints[j].position, b.joints[j].position);  // bit-exact (17 digits)
      EXPECT_EQ(a.joints[j].orientation.coeffs(), b.joints[j].orientation.coeffs());
      EXPECT_EQ(a.joints[j].confidence, b.joints[j].confidence);
    }
  }
}

TEST(Readers, GenericCsvRejectsUnknownAndMissingColumns) {
  auto error = [](const std::string& text) {
    try {
      read_recording(Format::Generic, write_file("g.csv", text));
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("stamp_ns,sensor_id\n").find("g.csv:1: expected the first line to be '# skelgraph skeleton csv v1'"),
            std::string::npos);
  EXPECT_NE(error("# skelgraph skeleton csv v1\nstamp_ns,sensor_id,person_id,colour\n").find("unknown column 'colour'"),
            std::string::npos);
  EXPECT_NE(error("# skelgraph skeleton csv v1\nstamp_ns,sensor_id,person_id\n").find("missing column 'head_x'"),
            std::string::npos);
  EXPECT_NE(error("# skelgraph skeleton csv v1\n# no colon\n").find("g.csv:2: expected a metadata line"),
            std::string::npos);
}

TEST(Readers, FormatNames) {
  for (const auto& n : format_names()) {
    ASSERT_TRUE(format_from_name(n).has_value()) << n;
    EXPECT_EQ(format_name(*format_from_name(n)), n);
  }
  EXPECT_FALSE(format_from_name("bvh").has_value());
}

// ---- the real recordings in ../shared/data (never copied into the project) ----

TEST(SharedData, KinderGatorAdultsAllReadWithTheDocumentedFrameCount) {
  const auto dir = fs::path(data_dir()) / "kinder-gator" / "adults";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)";
  std::size_t files = 0, frames = 0, facing = 0, head_above_torso = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".csv") continue;
    const auto rec = read_recording(Format::KinderGator, e.path().string());
    ++files;
    frames += rec.frames.size();
    EXPECT_FALSE(rec.metadata.at("action").empty());
    for (const auto& s : rec.frames) {
      facing += s[JointId::LeftShoulder].position.x() < s[JointId::RightShoulder].position.x() ? 1 : 0;
      head_above_torso += s[JointId::Head].position.y() > s[JointId::Torso].position.y() ? 1 : 0;
      EXPECT_GT(s[JointId::Torso].position.z(), 1.0);  // metres from the sensor
      EXPECT_LT(s[JointId::Torso].position.z(), 4.5);
    }
  }
  EXPECT_EQ(files, 160u);
  EXPECT_EQ(frames, 26675u);      // the data set's README
  EXPECT_EQ(facing, frames);      // README: ShoulderLeft X < ShoulderRight X in every frame
  EXPECT_EQ(head_above_torso, frames);  // y up
}

TEST(SharedData, LabanKinectV2FilesRead) {
  const auto dir = fs::path(data_dir()) / "laban";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing";
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const auto name = e.path().filename().string();
    if (e.path().extension() != ".csv") continue;
    const auto rec = read_recording(Format::KinectV2, e.path().string());
    ++files;
    ASSERT_GT(rec.frames.size(), 10u) << name;
    // Ges<NN>_<gesture>.csv carry their label; joints.csv is the unlabelled sample.
    EXPECT_EQ(rec.metadata.count("gesture"), name.rfind("Ges", 0) == 0 ? 1u : 0u) << name;
    for (const auto& s : rec.frames) {
      EXPECT_GT(s[JointId::Head].position.y(), s[JointId::Torso].position.y()) << name;
      EXPECT_GT(s[JointId::Head].confidence, 0.0f) << name;  // README: state 0 never occurs
    }
  }
  EXPECT_EQ(files, 7u);
}

// ---- KinectMultiTrack and gesture-phase ----

namespace {
std::string mt_header() {
  const char* joints[] = {"AnkleLeft", "AnkleRight", "ElbowLeft", "ElbowRight", "FootLeft", "FootRight", "HandLeft",
                          "HandRight", "HandTipLeft", "HandTipRight", "Head", "HipLeft", "HipRight", "KneeLeft",
                          "KneeRight", "Neck", "ShoulderLeft", "ShoulderRight", "SpineBase", "SpineMid",
                          "SpineShoulder", "ThumbLeft", "ThumbRight", "WristLeft", "WristRight"};
  std::string h = "Study_Id, Kinect_Config, Scenario_Id, Tracker_Time, Person_Id, Skeleton_Id, Skeleton_Time, "
                  "Skeleton_Init_Angle, Skeleton_Init_Dist, Kinect_Id, Kinect_Tilt_Angle, Kinect_Height";
  for (const auto* j : joints) h += std::string(", ") + j + "_X, " + j + "_Y, " + j + "_Z";
  return h + "\n";
}
// Joint j at (j, 1 + j/100, 2); joint `zero` (alphabetical index) at exactly 0, 0, 0.
std::string mt_row(long long tracker_ms, int person, const std::string& ip, int zero = -1) {
  std::ostringstream os;
  os << "1, 2, 6, " << tracker_ms << ", " << person << ", 0, 156019166051, -1.19, 2.36, " << ip << ", 0, 100";
  for (int j = 0; j < 25; ++j) {
    if (j == zero) {
      os << ", 0, 0, 0";
    } else {
      os << ", " << j << ", " << 1 + j / 100.0 << ", 2";
    }
  }
  return os.str() + "\n";
}
}  // namespace

TEST(Readers, MultiTrackTwoSensorsPeopleAndMissingJoints) {
  const long long t0 = 63562190843413LL;  // ms since 0001-01-01
  const auto path = write_file("mt.csv", mt_header() + mt_row(t0, 0, "138.251.207.136") +
                                             mt_row(t0, 0, "138.251.213.82", 20) + mt_row(t0 + 34, 1, "138.251.207.136"));
  const auto rec = read_recording(Format::MultiTrack, path);
  ASSERT_EQ(rec.frames.size(), 3u);
  EXPECT_EQ(rec.frames[0].sensor_id, "kinect_138_251_207_136");
  EXPECT_EQ(rec.frames[1].sensor_id, "kinect_138_251_213_82");
  EXPECT_EQ(rec.frames[2].person_id, 1u);
  EXPECT_EQ(rec.frames[0].stamp_ns, (t0 - 62135596800000LL) * 1000000LL);
  EXPECT_EQ(rec.frames[0].stamp_ns, rec.frames[1].stamp_ns);  // one tracker update, two sensors
  // Head is alphabetical joint 10, neck SpineShoulder (20), torso SpineMid (19).
  EXPECT_DOUBLE_EQ(rec.frames[0][JointId::Head].position.x(), 10.0);
  EXPECT_DOUBLE_EQ(rec.frames[0][JointId::Neck].position.x(), 20.0);
  EXPECT_DOUBLE_EQ(rec.frames[0][JointId::Torso].position.x(), 19.0);
  EXPECT_EQ(rec.frames[1][JointId::Neck].confidence, skeleton::kLost);  // exact zeros mean missing
  EXPECT_EQ(rec.frames[1][JointId::Head].confidence, skeleton::kTracked);
  EXPECT_EQ(rec.metadata.at("scenarios"), "6");
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("left_wrist")[0].x(), 23.0);  // WristLeft is alphabetical joint 23
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("right_wrist")[2].x(), 24.0);
  const auto no_wrist = read_recording(Format::MultiTrack, write_file("mt_wrist.csv", mt_header() + mt_row(t0, 0, "1.2.3.4", 23)));
  EXPECT_TRUE(no_wrist.extra_joints.at("left_wrist")[0].array().isNaN().all());  // missing: NaN

  std::string bad_header = mt_header();
  bad_header.replace(bad_header.find("Head_X"), 6, "Hand_X");
  try {
    read_recording(Format::MultiTrack, write_file("mt_bad.csv", bad_header));
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("mt_bad.csv:1: expected column 43 to be 'Head_X', got 'Hand_X'"),
              std::string::npos)
        << e.what();
  }
}

TEST(Readers, GesturePhasePackedClockBomCrlfAndLabels) {
  const std::string header = "\xEF\xBB\xBFlhx,lhy,lhz,rhx,rhy,rhz,hx,hy,hz,sx,sy,sz,lwx,lwy,lwz,rwx,rwy,rwz,timestamp,phase\r\n";
  const std::string pos = "1,4.5,2.2,3,4.4,2.3,2.4,0.9,2.4,2.5,3.5,2.4,1.9,4.5,2.2,3.2,4.2,2.3";
  const auto path = write_file("gp.csv", header + pos + ",4159973,Rest\r\n" + pos + ",4200004,Prepara\xC3\xA7\xC3\xA3o\r\n");
  const auto rec = read_recording(Format::GesturePhase, path);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.frames[1].stamp_ns - rec.frames[0].stamp_ns, 31'000'000);  // 41:59.973 -> 42:00.004
  EXPECT_EQ(rec.frame_labels, (std::vector<std::string>{"Rest", "Preparation"}));
  EXPECT_DOUBLE_EQ(rec.frames[0][JointId::Head].position.y(), -0.9);  // y flipped to point up
  EXPECT_DOUBLE_EQ(rec.frames[0][JointId::LeftHand].position.x(), 1.0);
  EXPECT_EQ(rec.frames[0][JointId::LeftElbow].confidence, skeleton::kLost);  // not in the format
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("left_wrist")[0].x(), 1.9);
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("right_wrist")[0].y(), -4.2);  // flipped too

  EXPECT_THROW(read_recording(Format::GesturePhase, write_file("gp_bad.csv", header + pos + ",4175973,Rest\r\n")),
               DataError);  // 41:75.973 is no clock reading
}

TEST(SharedData, MultiTrackFilesReadWithDocumentedRowsAndSensors) {
  const auto dir = fs::path(data_dir()) / "kinect-multitrack";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing";
  const std::map<std::string, std::size_t> rows = {
      {"Study_12_Kinect_0_Time_4_55_27_PM.csv", 4550}, {"Study_12_Kinect_1_Time_4_58_35_PM.csv", 3452},
      {"Study_12_Kinect_2_Time_5_01_13_PM.csv", 3434}, {"Study_12_Kinect_2_Time_5_04_00_PM.csv", 34},
      {"Study_12_Kinect_2_Time_5_04_54_PM.csv", 52},   {"Study_14_Kinect_0_Time_5_43_18_PM.csv", 4098},
      {"Study_14_Kinect_1_Time_5_47_14_PM.csv", 3588}, {"Study_14_Kinect_2_Time_5_50_02_PM.csv", 3392},
      {"Study_14_Kinect_2_Time_5_52_45_PM.csv", 44},   {"Study_1_Kinect_2_Time_12_03_46_PM.csv", 3710},
      {"Study_1_Kinect_2_Time_12_07_07_PM.csv", 724},  {"Study_22_Kinect_1_Time_2_16_21_PM.csv", 1993},
      {"Study_24_Kinect_1_Time_2_49_46_PM.csv", 1891}};
  std::size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.path().extension() != ".csv") continue;
    const auto name = e.path().filename().string();
    const auto rec = read_recording(Format::MultiTrack, e.path().string());
    ++files;
    ASSERT_EQ(rows.count(name), 1u) << name;
    EXPECT_EQ(rec.frames.size(), rows.at(name)) << name;
    std::set<std::string> sensors;
    std::size_t lost = 0;
    for (const auto& s : rec.frames) {
      sensors.insert(s.sensor_id);
      for (const auto& j : s.joints) lost += j.confidence == skeleton::kLost ? 1 : 0;
    }
    EXPECT_EQ(sensors.size(), 2u) << name;
    // README: only Study_22 has exact-zero joints; 18 of them fall on canonical joints
    // (SpineShoulder 7, ShoulderLeft 4, ShoulderRight 3, HipLeft 2, HipRight 1, SpineMid 1).
    EXPECT_EQ(lost, name.rfind("Study_22", 0) == 0 ? 18u : 0u) << name;
    if (name == "Study_1_Kinect_2_Time_12_03_46_PM.csv") {
      EXPECT_EQ(rec.frames.front().stamp_ns / 1'000'000'000LL, 1426593867LL);  // 2015-03-17 12:04:27 UTC
    }
  }
  EXPECT_EQ(files, rows.size());
}

TEST(SharedData, GesturePhaseFilesReadWithDocumentedFramesAndLabels) {
  const auto dir = fs::path(data_dir()) / "gesture-phase";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing";
  const std::map<std::string, std::size_t> frames = {{"a1_raw.csv", 1747}, {"a2_raw.csv", 1264},
                                                     {"a3_raw.csv", 1834}, {"b1_raw.csv", 1073},
                                                     {"b3_raw.csv", 1424}, {"c1_raw.csv", 1111},
                                                     {"c3_raw.csv", 1448}};
  for (const auto& [name, n] : frames) {
    const auto rec = read_recording(Format::GesturePhase, (dir / name).string());
    EXPECT_EQ(rec.frames.size(), n) << name;
    ASSERT_EQ(rec.frame_labels.size(), n) << name;
    for (const auto& s : rec.frames) EXPECT_GT(s[JointId::Head].position.y(), s[JointId::Torso].position.y()) << name;
    std::map<std::string, std::size_t> count;
    for (const auto& l : rec.frame_labels) ++count[l];
    if (name == "a3_raw.csv") {
      EXPECT_EQ(count, (std::map<std::string, std::size_t>{
                           {"Rest", 662}, {"Stroke", 535}, {"Preparation", 279}, {"Retraction", 208}, {"Hold", 150}}));
    }
    if (name == "b1_raw.csv") {
      EXPECT_EQ(count["Preparation"], 412u);  // 411 + the one Portuguese spelling
    }
    if (name == "a1_raw.csv") {
      EXPECT_EQ(count, (std::map<std::string, std::size_t>{{"G", 1049}, {"E", 698}}));
    }
  }
}

// MSRC-12: space-separated, CRLF, µs, 20 joints x/y/z/w; all-zero lines carry no
// skeleton; the .tagstream beside a file gives its action points.
TEST(Readers, Msrc12SpacesZeroFramesAndTagstream) {
  std::ostringstream os;
  const auto row = [&](long long us, double base) {
    os << us;
    for (int j = 0; j < 20; ++j) os << " " << base + j << " " << 0.1 * j << " " << 2.5 << " 1.000000";
    os << "\r\n";
  };
  os << "0";
  for (int j = 0; j < 80; ++j) os << " 0";
  os << "\r\n";
  row(33000, 0.0);
  row(66000, 0.5);
  const auto path = write_file("P1_1_9_p42.csv", os.str());
  write_file("P1_1_9_p42.tagstream", "XQPCTick;Tag\r\n2493750;G9  Start system\r\n4987500;G9  Start system\r\n");
  const auto rec = read_recording(Format::Msrc12, path);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.report.empty_frames, 1u);
  EXPECT_EQ(rec.frames[0].stamp_ns, 33'000'000);
  // Kinect v1 order: HandRight (11) is the canonical right hand; its x is base + 11.
  EXPECT_DOUBLE_EQ(rec.frames[1][JointId::RightHand].position.x(), 11.5);
  EXPECT_DOUBLE_EQ(rec.extra_joints.at("right_wrist")[1].x(), 10.5);
  EXPECT_EQ(rec.metadata.at("subject"), "p42");
  EXPECT_EQ(rec.metadata.at("gesture"), "G9  Start system");
  ASSERT_EQ(rec.annotations.size(), 2u);
  EXPECT_EQ(rec.annotations[0].start_ns, 50'000'000);  // (2493750 * 1000 + 24937) / 49875 us
  EXPECT_EQ(rec.annotations[1].end_ns, 100'000'000);
  // Bad input names file:line.
  const auto bad = write_file("P1_1_9_p43.csv", "33000 1 2 3\r\n");
  try {
    read_recording(Format::Msrc12, bad);
    ADD_FAILURE() << "a short line was read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("P1_1_9_p43.csv:1: expected 81 fields"), std::string::npos) << e.what();
  }
  const auto tags = write_file("t.tagstream", "XQPCTick;Tag\r\n4987500;G9\r\n2493750;G9\r\n");
  try {
    read_tagstream(tags);
    ADD_FAILURE() << "ticks going backwards were read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("t.tagstream:3: ticks go backwards"), std::string::npos) << e.what();
  }
}

// The 18 MSRC-12 files: frames and tags as the data set's README counts them;
// the one file without a single skeleton is bad input.
TEST(SharedData, Msrc12FilesReadWithDocumentedFramesAndTags) {
  const auto dir = fs::path(data_dir()) / "msrc12";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)";
  struct Want {
    const char* file;
    std::size_t lines, zero, tags;
  };
  for (const Want w : {Want{"P1_1_1_p06", 1027, 20, 9}, Want{"P1_1_10_p06", 3538, 2035, 10}, Want{"P1_1_11_p21", 2614, 20, 12},
                       Want{"P1_1_12_p19", 923, 23, 10}, Want{"P1_1_1A_p21", 921, 20, 10}}) {
    const auto rec = read_recording(Format::Msrc12, (dir / (std::string(w.file) + ".csv")).string());
    EXPECT_EQ(rec.report.lines, w.lines) << w.file;
    EXPECT_EQ(rec.report.empty_frames, w.zero) << w.file;
    EXPECT_EQ(rec.frames.size(), w.lines - w.zero) << w.file;
    ASSERT_EQ(rec.annotations.size(), w.tags) << w.file;
    // Every tag falls inside its sequence's time range.
    for (const auto& a : rec.annotations) {
      EXPECT_GE(a.start_ns, rec.frames.front().stamp_ns - 2'100'000'000) << w.file;
      EXPECT_LE(a.start_ns, rec.frames.back().stamp_ns) << w.file;
    }
  }
  try {
    read_recording(Format::Msrc12, (dir / "P1_1_12A_p19.csv").string());
    ADD_FAILURE() << "an all-zero file read as a recording";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("P1_1_12A_p19.csv:1029: no skeleton frames"), std::string::npos) << e.what();
  }
}

// Annotations for any recording: a CSV beside it (seconds or frames), per-frame
// labels as ranges; the CSV beside a file wins over the format's own.
TEST(Readers, AnnotationCsvAndFrameLabels) {
  std::ostringstream os;
  for (int t = 0; t < 4; ++t) {
    os << t * 33000;
    for (int j = 0; j < 20; ++j) os << " " << 0.1 * j << " 1 2.5 1";
    os << "\r\n";
  }
  const auto path = write_file("P1_1_8_p07.csv", os.str());
  fs::remove(::testing::TempDir() + "/P1_1_8_p07.annotations.csv");  // left by an earlier run
  write_file("P1_1_8_p07.tagstream", "XQPCTick;Tag\r\n4987500;G8\r\n");
  auto rec = read_recording(Format::Msrc12, path);
  ASSERT_EQ(annotations_of(rec).size(), 1u);  // the tagstream
  const auto seconds = write_file("s.csv", "label,start_s,end_s\nwave,0.05,0.066\npoint,0,0\n");
  const auto a = read_annotation_csv(seconds, rec);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].label, "point");  // in time order
  EXPECT_EQ(a[1].start_ns, 50'000'000);
  EXPECT_EQ(a[1].end_ns, 66'000'000);
  const auto frames = write_file("f.csv", "label,start_frame,end_frame\nwave,1,3\n");
  const auto b = read_annotation_csv(frames, rec);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].start_ns, 33'000'000);
  EXPECT_EQ(b[0].end_ns, 99'000'000);
  const auto error = [&](const std::string& text) {
    try {
      read_annotation_csv(write_file("bad.csv", text), rec);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("label,start_frame,end_frame\nwave,1,4\n").find("bad.csv:2: end_frame 4 is outside the recording's 4 frames"),
            std::string::npos);
  EXPECT_NE(error("label,start_s,end_s\nwave,0.5,0.1\n").find("bad.csv:2: the annotation ends before it starts"), std::string::npos);
  EXPECT_NE(error("name,from,to\n").find("bad.csv:1: expected a header"), std::string::npos);
  // Beside the file, it wins over the tagstream.
  write_file("P1_1_8_p07.annotations.csv", "label,start_frame,end_frame\nwave,1,3\nwave,3,3\n");
  EXPECT_EQ(annotations_of(rec).size(), 2u);
  // Per-frame labels: runs, rest left out.
  Recording phases;
  phases.source = ::testing::TempDir() + "/phases.csv";
  for (int t = 0; t < 6; ++t) {
    skelgraph::skeleton::Skeleton s;
    s.stamp_ns = t * 10;
    phases.frames.push_back(s);
  }
  phases.frame_labels = {"Rest", "Stroke", "Stroke", "Hold", "Rest", "Stroke"};
  const auto runs = annotations_from_frame_labels(phases);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(runs[0].label, "Stroke");
  EXPECT_EQ(runs[0].start_ns, 10);
  EXPECT_EQ(runs[0].end_ns, 20);
  EXPECT_EQ(runs[2].start_ns, 50);
}

// The generic CSV keeps every joint a sensor gives: real Kinect v2 and
// KinectMultiTrack files through it and back, untracked joints (NaN) included.
TEST(SharedData, GenericCsvKeepsEveryJointOfRealFiles) {
  const auto data = fs::path(data_dir());
  const std::vector<std::pair<Format, fs::path>> files = {
      {Format::KinectV2, data / "laban" / "Ges05_demopoint.csv"},
      {Format::MultiTrack, data / "kinect-multitrack" / "Experiments_1_2_3_6" / "Study_12_Kinect_2_Time_5_01_13_PM.csv"},
      {Format::Msrc12, data / "msrc12" / "P1_1_10_p19.csv"}};
  for (const auto& [format, path] : files) {
    ASSERT_TRUE(fs::exists(path)) << path << " is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)";
    const auto rec = read_recording(format, path.string());
    EXPECT_GE(rec.extra_joints.size(), format == Format::Msrc12 ? 5u : 10u) << path;
    std::ostringstream os;
    write_generic_csv(rec, os);
    const auto back = read_recording(Format::Generic, write_file("extras.csv", os.str()));
    ASSERT_EQ(back.frames.size(), rec.frames.size()) << path;
    ASSERT_EQ(back.extra_joints.size(), rec.extra_joints.size()) << path;
    std::size_t missing = 0;
    for (const auto& [name, points] : rec.extra_joints) {
      const auto& got = back.extra_joints.at(name);
      ASSERT_EQ(got.size(), points.size()) << name;
      for (std::size_t t = 0; t < points.size(); ++t) {
        for (Eigen::Index k = 0; k < 3; ++k) {
          if (std::isnan(points[t][k])) {
            EXPECT_TRUE(std::isnan(got[t][k])) << name << " frame " << t;
            ++missing;
          } else {
            EXPECT_DOUBLE_EQ(got[t][k], points[t][k]) << name << " frame " << t;
          }
        }
      }
    }
    if (format == Format::Msrc12) {
      EXPECT_EQ(missing, 0u);
    }
  }
}
