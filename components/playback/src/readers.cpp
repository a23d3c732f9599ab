#include "skelgraph/playback/readers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <regex>
#include <set>

namespace skelgraph::playback {

namespace fs = std::filesystem;
using skeleton::JointId;
using skeleton::kJointCount;

const char* format_name(Format f) {
  switch (f) {
    case Format::Generic: return "generic";
    case Format::KinderGator: return "kinder-gator";
    case Format::KinectV2: return "kinect-v2";
    case Format::MultiTrack: return "multitrack";
    case Format::GesturePhase: return "gesture-phase";
    case Format::Msrc12: return "msrc12";
  }
  return "?";
}

constexpr Format kFormats[] = {Format::Generic, Format::KinderGator, Format::KinectV2, Format::MultiTrack,
                               Format::GesturePhase, Format::Msrc12};

std::vector<std::string> format_names() {
  std::vector<std::string> out;
  for (auto f : kFormats) out.push_back(format_name(f));
  return out;
}

std::optional<Format> format_from_name(std::string_view name) {
  for (auto f : kFormats) {
    if (name == format_name(f)) return f;
  }
  return std::nullopt;
}

namespace {

constexpr std::size_t kMaxProblems = 20;

Recording empty_recording(Format format, const std::string& path) {
  Recording rec;
  rec.format = format_name(format);
  rec.source = path;
  return rec;
}

// Reads every data row with the error policy applied: `parse` turns one row
// into zero or more skeletons (appended to rec.frames) or throws DataError.
template <class Parse>
void read_rows(CsvReader& csv, const ReadOptions& opt, Recording& rec, Parse parse) {
  std::vector<std::string> fields;
  while (csv.next(fields)) {
    ++rec.report.lines;
    const auto before = rec.frames.size();
    try {
      parse(fields);
      for (auto i = std::max<std::size_t>(before, 1); i < rec.frames.size(); ++i) {
        const auto prev = rec.frames[i - 1].stamp_ns, now = rec.frames[i].stamp_ns;
        if (now < prev) {
          csv.fail("time goes backwards (" + std::to_string(now) + " ns after " + std::to_string(prev) +
                   " ns); expected non-decreasing timestamps");
        }
        if (now == prev && i >= before) ++rec.report.repeated_stamps;
      }
    } catch (const DataError& e) {
      if (opt.on_error == ReadOptions::OnError::Stop) throw;
      rec.frames.resize(before);
      if (rec.frame_labels.size() > before) rec.frame_labels.resize(before);
      for (auto& [name, points] : rec.extra_joints)
        if (points.size() > before) points.resize(before);
      ++rec.report.skipped;
      if (rec.report.problems.size() < kMaxProblems) rec.report.problems.push_back(e.what());
    }
  }
  rec.report.last_line = csv.line();
}

// The wrists of the frame about to be appended (call just before rec.frames.push_back).
void add_wrists(Recording& rec, const Eigen::Vector3d& left, const Eigen::Vector3d& right) {
  rec.extra_joints["left_wrist"].push_back(left);
  rec.extra_joints["right_wrist"].push_back(right);
}

// Every other joint the sensor gives beyond the canonical 15 and the wrists
// (extra joint name, source index), for the frame about to be appended.
template <class Position>
void add_extras(Recording& rec, const std::vector<std::pair<const char*, std::size_t>>& extras, Position position) {
  for (const auto& [name, src] : extras) rec.extra_joints[name].push_back(position(src));
}
// Kinect v1 (NUI order): the hip centre and the ankles.
const std::vector<std::pair<const char*, std::size_t>> kV1Extras = {{"pelvis", 0}, {"left_ankle", 14}, {"right_ankle", 18}};

void expect_fields(const CsvReader& csv, const std::vector<std::string>& f, std::size_t n, const char* what) {
  if (f.size() != n) {
    csv.fail("expected " + std::to_string(n) + " fields (" + what + "), got " + std::to_string(f.size()));
  }
}

Eigen::Vector3d xyz(const CsvReader& csv, const std::vector<std::string>& f, std::size_t i, const std::string& name) {
  return {csv.number(f, i, name + "X"), csv.number(f, i + 1, name + "Y"), csv.number(f, i + 2, name + "Z")};
}

// ---- Kinder-Gator (Kinect v1, NUI joint order) ----

const std::array<const char*, 20> kV1Joints = {
    "HipCenter", "Spine",    "ShoulderCenter", "Head",       "ShoulderLeft", "ElbowLeft", "WristLeft",
    "HandLeft",  "ShoulderRight", "ElbowRight", "WristRight", "HandRight",   "HipLeft",   "KneeLeft",
    "AnkleLeft", "FootLeft", "HipRight",       "KneeRight",  "AnkleRight",   "FootRight"};
// Canonical joint i comes from Kinect v1 joint kV1Map[i].
const std::array<std::size_t, kJointCount> kV1Map = {3, 2, 1, 4, 5, 7, 8, 9, 11, 12, 13, 15, 16, 17, 19};

Recording read_kinder_gator(const std::string& path, const ReadOptions& opt) {
  auto rec = empty_recording(Format::KinderGator, path);
  CsvReader csv(path);
  std::vector<std::string> header;
  if (!csv.next(header)) csv.fail("empty file; expected a header starting with 'Timestamp'");
  expect_fields(csv, header, 63, "Timestamp, 20 joints x X/Y/Z, User-ID, Action");
  if (header[0] != "Timestamp") csv.fail("expected the header to start with 'Timestamp', got '" + header[0] + "'");
  for (std::size_t j = 0; j < kV1Joints.size(); ++j) {
    const std::string want = std::string(kV1Joints[j]) + "X";
    if (header[1 + 3 * j] != want) {
      csv.fail("expected column " + std::to_string(2 + 3 * j) + " to be '" + want + "', got '" + header[1 + 3 * j] + "'");
    }
  }
  // Timestamps are ms since midnight UTC; the file name's Unix ms gives the day.
  std::int64_t day_ns = 0;
  std::smatch m;
  const auto name = fs::path(path).filename().string();
  if (std::regex_search(name, m, std::regex("-([0-9]{13})\\.csv$"))) {
    const auto file_ms = std::stoll(m[1].str());
    day_ns = (file_ms / 86'400'000LL) * 86'400'000LL * 1'000'000LL;
  }
  const std::string sensor = opt.sensor_id.empty() ? "kinect_v1" : opt.sensor_id;
  read_rows(csv, opt, rec, [&](const std::vector<std::string>& f) {
    expect_fields(csv, f, 63, "Timestamp, 20 joints x X/Y/Z, User-ID, Action");
    skeleton::Skeleton s;
    s.sensor_id = sensor;
    s.frame_id = sensor;
    s.stamp_ns = day_ns + static_cast<std::int64_t>(std::llround(csv.number(f, 0, "Timestamp") * 1e6));
    s.frame_number = rec.frames.size();
    for (std::size_t i = 0; i < kJointCount; ++i) {
      const auto src = kV1Map[i];
      s.joints[i].position = xyz(csv, f, 1 + 3 * src, kV1Joints[src]);
      s.joints[i].confidence = skeleton::kTracked;  // the format has no tracking state
    }
    if (rec.metadata.empty()) {
      rec.metadata["subject"] = f[61];
      rec.metadata["action"] = f[62];
    }
    add_wrists(rec, xyz(csv, f, 1 + 3 * 6, kV1Joints[6]), xyz(csv, f, 1 + 3 * 10, kV1Joints[10]));
    add_extras(rec, kV1Extras, [&](std::size_t j) { return xyz(csv, f, 1 + 3 * j, kV1Joints[j]); });
    rec.frames.push_back(std::move(s));
  });
  return rec;
}

// ---- MSRC-12 (Kinect v1, NUI joint order; space-separated; .tagstream beside) ----

Recording read_msrc12(const std::string& path, const ReadOptions& opt) {
  auto rec = empty_recording(Format::Msrc12, path);
  CsvReader csv(path, ' ');
  const std::string sensor = opt.sensor_id.empty() ? "kinect_v1" : opt.sensor_id;
  std::smatch m;
  const auto stem = fs::path(path).stem().string();
  if (std::regex_search(stem, m, std::regex("_(p[0-9]+)$"))) rec.metadata["subject"] = m[1].str();
  auto tags = fs::path(path).replace_extension(".tagstream");
  if (fs::exists(tags)) {
    rec.annotations = read_tagstream(tags.string());
    if (!rec.annotations.empty()) rec.metadata["gesture"] = rec.annotations.front().label;
  }
  read_rows(csv, opt, rec, [&](const std::vector<std::string>& f) {
    expect_fields(csv, f, 81, "time in microseconds, 20 joints x X/Y/Z/W");
    const auto us = csv.integer(f, 0, "time");
    bool any = false;
    for (std::size_t i = 1; i < f.size() && !any; ++i) any = csv.number(f, i, "joint value") != 0.0;
    if (!any) {  // all zeros: no skeleton in this frame
      ++rec.report.empty_frames;
      return;
    }
    const auto joint = [&](std::size_t j) {
      const std::string name = kV1Joints[j];
      return Eigen::Vector3d(csv.number(f, 1 + 4 * j, name + " x"), csv.number(f, 2 + 4 * j, name + " y"),
                             csv.number(f, 3 + 4 * j, name + " z"));
    };
    skeleton::Skeleton s;
    s.sensor_id = sensor;
    s.frame_id = sensor;
    s.stamp_ns = us * 1000;
    s.frame_number = rec.frames.size();
    for (std::size_t i = 0; i < kJointCount; ++i) {
      s.joints[i].position = joint(kV1Map[i]);
      s.joints[i].confidence = skeleton::kTracked;  // the format has no tracking state
    }
    add_wrists(rec, joint(6), joint(10));
    add_extras(rec, kV1Extras, joint);
    rec.frames.push_back(std::move(s));
  });
  return rec;
}

// ---- Kinect v2 body file (JointType order, with TrackingState) ----

const std::array<const char*, 25> kV2Joints = {
    "SpineBase",  "SpineMid",  "Neck",      "Head",         "ShoulderLeft", "ElbowLeft",  "WristLeft",
    "HandLeft",   "ShoulderRight", "ElbowRight", "WristRight", "HandRight",  "HipLeft",    "KneeLeft",
    "AnkleLeft",  "FootLeft",  "HipRight",  "KneeRight",    "AnkleRight",   "FootRight",  "SpineShoulder",
    "HandTipLeft", "ThumbLeft", "HandTipRight", "ThumbRight"};
// Neck is SpineShoulder (between the shoulders, where NITE and Kinect v1 put it),
// torso is SpineMid.
const std::array<std::size_t, kJointCount> kV2Map = {3, 20, 1, 4, 5, 7, 8, 9, 11, 12, 13, 15, 16, 17, 19};

// Kinect v2 (JointType order): spine base, the upper neck, ankles, hand tips and thumbs.
const std::vector<std::pair<const char*, std::size_t>> kV2Extras = {
    {"pelvis", 0},          {"upper_neck", 2},  {"left_ankle", 14},     {"right_ankle", 18},
    {"left_hand_tip", 21},  {"left_thumb", 22}, {"right_hand_tip", 23}, {"right_thumb", 24}};

Recording read_kinect_v2(const std::string& path, const ReadOptions& opt) {
  auto rec = empty_recording(Format::KinectV2, path);
  CsvReader csv(path);
  std::smatch m;
  const auto stem = fs::path(path).stem().string();
  if (std::regex_match(stem, m, std::regex("Ges[0-9]+_(.+)"))) rec.metadata["gesture"] = m[1].str();
  const std::string sensor = opt.sensor_id.empty() ? "kinect_v2" : opt.sensor_id;
  read_rows(csv, opt, rec, [&](const std::vector<std::string>& f) {
    expect_fields(csv, f, 101, "Timestamp, 25 joints x X/Y/Z/TrackingState");
    skeleton::Skeleton s;
    s.sensor_id = sensor;
    s.frame_id = sensor;
    s.stamp_ns = csv.integer(f, 0, "Timestamp") * 100;  // 100-ns sensor ticks
    s.frame_number = rec.frames.size();
    for (std::size_t i = 0; i < kJointCount; ++i) {
      const auto src = kV2Map[i];
      const auto col = 1 + 4 * src;
      s.joints[i].position = xyz(csv, f, col, kV2Joints[src]);
      const auto state = csv.integer(f, col + 3, std::string(kV2Joints[src]) + "TrackingState");
      if (state < 0 || state > 2) {
        csv.fail(std::string(kV2Joints[src]) + "TrackingState expects 0, 1 or 2, got " + std::to_string(state));
      }
      s.joints[i].confidence = state == 2 ? skeleton::kTracked : state == 1 ? skeleton::kInferred : skeleton::kLost;
    }
    // Wrists: only where the sensor tracked them (the canonical joints keep inferred ones with confidence 0.5).
    const auto wrist = [&](std::size_t src) {
      const auto col = 1 + 4 * src;
      const bool tracked = csv.integer(f, col + 3, std::string(kV2Joints[src]) + "TrackingState") == 2;
      return tracked ? xyz(csv, f, col, kV2Joints[src]) : Eigen::Vector3d::Constant(std::nan(""));
    };
    add_wrists(rec, wrist(6), wrist(10));
    add_extras(rec, kV2Extras, wrist);
    rec.frames.push_back(std::move(s));
  });
  return rec;
}

// ---- KinectMultiTrack (two Kinect v2 sensors, alphabetical joint order) ----

const std::array<const char*, 25> kMtJoints = {
    "AnkleLeft", "AnkleRight", "ElbowLeft",  "ElbowRight", "FootLeft",   "FootRight",     "HandLeft",
    "HandRight", "HandTipLeft", "HandTipRight", "Head",    "HipLeft",    "HipRight",      "KneeLeft",
    "KneeRight", "Neck",       "ShoulderLeft", "ShoulderRight", "SpineBase", "SpineMid", "SpineShoulder",
    "ThumbLeft", "ThumbRight", "WristLeft",  "WristRight"};
// Same choices as for Kinect v2 above: neck = SpineShoulder, torso = SpineMid.
const std::array<std::size_t, kJointCount> kMtMap = {10, 20, 19, 16, 2, 6, 17, 3, 7, 11, 13, 4, 12, 14, 5};
constexpr std::size_t kMtFields = 12 + 3 * 25;
constexpr std::int64_t kDotNetEpochToUnixMs = 62'135'596'800'000LL;  // ms from 0001-01-01 to 1970-01-01

// The same extra joints as Kinect v2, in the data set's alphabetical order.
const std::vector<std::pair<const char*, std::size_t>> kMtExtras = {
    {"pelvis", 18},         {"upper_neck", 15}, {"left_ankle", 0},      {"right_ankle", 1},
    {"left_hand_tip", 8},   {"left_thumb", 21}, {"right_hand_tip", 9},  {"right_thumb", 22}};

Recording read_multitrack(const std::string& path, const ReadOptions& opt) {
  auto rec = empty_recording(Format::MultiTrack, path);
  CsvReader csv(path);
  std::vector<std::string> header;
  if (!csv.next(header)) csv.fail("empty file; expected a header starting with 'Study_Id'");
  expect_fields(csv, header, kMtFields, "12 columns, then 25 joints x X/Y/Z");
  const std::array<const char*, 12> first = {"Study_Id", "Kinect_Config", "Scenario_Id", "Tracker_Time",
                                             "Person_Id", "Skeleton_Id",   "Skeleton_Time", "Skeleton_Init_Angle",
                                             "Skeleton_Init_Dist", "Kinect_Id", "Kinect_Tilt_Angle", "Kinect_Height"};
  for (std::size_t i = 0; i < first.size(); ++i) {
    if (header[i] != first[i]) csv.fail("expected column " + std::to_string(i + 1) + " to be '" + first[i] + "', got '" + header[i] + "'");
  }
  for (std::size_t j = 0; j < kMtJoints.size(); ++j) {
    const std::string want = std::string(kMtJoints[j]) + "_X";
    if (header[12 + 3 * j] != want) {
      csv.fail("expected column " + std::to_string(13 + 3 * j) + " to be '" + want + "', got '" + header[12 + 3 * j] + "'");
    }
  }
  // Each Kinect_Id (the sensor PC's IP address) becomes a sensor id.
  std::map<std::string, std::string> sensors;
  std::map<std::string, std::uint64_t> counts;
  std::set<std::string> scenarios;
  read_rows(csv, opt, rec, [&](const std::vector<std::string>& f) {
    expect_fields(csv, f, kMtFields, "12 columns, then 25 joints x X/Y/Z");
    const auto& ip = f[9];
    if (ip.empty()) csv.fail("column 'Kinect_Id' is empty; expected the sensor's IP address");
    auto it = sensors.find(ip);
    if (it == sensors.end()) {
      std::string id = opt.sensor_id.empty() ? "kinect_" + ip : opt.sensor_id + "_" + std::to_string(sensors.size());
      std::replace(id.begin(), id.end(), '.', '_');
      it = sensors.emplace(ip, id).first;
    }
    skeleton::Skeleton s;
    s.sensor_id = it->second;
    // Rows are already mapped into one reference skeleton's camera space (data README).
    s.frame_id = "multitrack_reference";
    const auto person = csv.integer(f, 4, "Person_Id");
    if (person < 0) csv.fail("Person_Id expects a non-negative integer, got " + f[4]);
    s.person_id = static_cast<std::uint32_t>(person);
    s.stamp_ns = (csv.integer(f, 3, "Tracker_Time") - kDotNetEpochToUnixMs) * 1'000'000LL;
    s.frame_number = counts[s.sensor_id + "/" + f[4]]++;
    scenarios.insert(f[2]);
    for (std::size_t i = 0; i < kJointCount; ++i) {
      const auto src = kMtMap[i];
      const std::string name = std::string(kMtJoints[src]) + "_";
      const Eigen::Vector3d p(csv.number(f, 12 + 3 * src, name + "X"), csv.number(f, 13 + 3 * src, name + "Y"),
                              csv.number(f, 14 + 3 * src, name + "Z"));
      // -9999 is the logger's "missing"; exact zeros appear instead in practice.
      const bool missing = (p.array() == -9999.0).any() || p.isZero(0.0);
      s.joints[i].position = missing ? Eigen::Vector3d::Zero() : p;
      s.joints[i].confidence = missing ? skeleton::kLost : skeleton::kTracked;
    }
    const auto wrist = [&](std::size_t src) {
      const std::string name = std::string(kMtJoints[src]) + "_";
      const Eigen::Vector3d p(csv.number(f, 12 + 3 * src, name + "X"), csv.number(f, 13 + 3 * src, name + "Y"),
                              csv.number(f, 14 + 3 * src, name + "Z"));
      const bool missing = (p.array() == -9999.0).any() || p.isZero(0.0);
      return missing ? Eigen::Vector3d::Constant(std::nan("")) : p;
    };
    add_wrists(rec, wrist(23), wrist(24));
    add_extras(rec, kMtExtras, wrist);
    if (rec.metadata.empty()) {
      rec.metadata["study"] = f[0];
      rec.metadata["kinect_config"] = f[1];
    }
    rec.frames.push_back(std::move(s));
  });
  std::string list;
  for (const auto& sc : scenarios) list += (list.empty() ? "" : ",") + sc;
  if (!list.empty()) rec.metadata["scenarios"] = list;
  for (const auto& [ip, id] : sensors) rec.metadata["sensor " + id] = ip;
  return rec;
}

// ---- UCI gesture-phase (6 points, y down, phase labels) ----

Recording read_gesture_phase(const std::string& path, const ReadOptions& opt) {
  auto rec = empty_recording(Format::GesturePhase, path);
  CsvReader csv(path);
  std::vector<std::string> header;
  if (!csv.next(header)) csv.fail("empty file; expected a header starting with 'lhx'");
  const std::vector<std::string> points = {"lhx", "lhy", "lhz", "rhx", "rhy", "rhz", "hx", "hy", "hz",
                                           "sx",  "sy",  "sz",  "lwx", "lwy", "lwz", "rwx", "rwy", "rwz"};
  const bool timed = header.size() == 20;
  if (header.size() != 19 && header.size() != 20) {
    csv.fail("expected 19 columns (18 positions, phase) or 20 (18 positions, timestamp, phase), got " +
             std::to_string(header.size()));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (header[i] != points[i]) csv.fail("expected column " + std::to_string(i + 1) + " to be '" + points[i] + "', got '" + header[i] + "'");
  }
  if (timed && header[18] != "timestamp") csv.fail("expected column 19 to be 'timestamp', got '" + header[18] + "'");
  if (header.back() != "phase") csv.fail("expected the last column to be 'phase', got '" + header.back() + "'");
  rec.metadata["time"] = timed ? "decoded from the packed mmssfff clock" : "none in the file: 30 Hz assumed";
  rec.metadata["units"] = "x, y scaled image coordinates (y flipped to point up), z metres";
  const std::string sensor = opt.sensor_id.empty() ? "kinect" : opt.sensor_id;
  // Canonical joint -> column of its x (the wrists go to extra_joints).
  const std::vector<std::pair<JointId, std::size_t>> map = {
      {JointId::LeftHand, 0}, {JointId::RightHand, 3}, {JointId::Head, 6}, {JointId::Torso, 9}};
  read_rows(csv, opt, rec, [&](const std::vector<std::string>& f) {
    expect_fields(csv, f, header.size(), timed ? "18 positions, timestamp, phase" : "18 positions, phase");
    skeleton::Skeleton s;
    s.sensor_id = sensor;
    s.frame_id = sensor;
    s.frame_number = rec.frames.size();
    if (timed) {
      const auto t = csv.integer(f, 18, "timestamp");
      if (t < 0 || t % 100000 >= 60000) csv.fail("timestamp expects a packed mmssfff clock, got " + f[18]);
      s.stamp_ns = ((t / 100000) * 60000 + t % 100000) * 1'000'000LL;
    } else {
      s.stamp_ns = static_cast<std::int64_t>(s.frame_number) * 33'333'333LL;
    }
    for (const auto& [joint, col] : map) {
      s[joint].position = {csv.number(f, col, points[col]), -csv.number(f, col + 1, points[col + 1]),
                           csv.number(f, col + 2, points[col + 2])};
      s[joint].confidence = skeleton::kTracked;
    }
    const auto wrist = [&](std::size_t col) {
      return Eigen::Vector3d(csv.number(f, col, points[col]), -csv.number(f, col + 1, points[col + 1]),
                             csv.number(f, col + 2, points[col + 2]));
    };
    auto phase = f.back();
    if (phase.empty()) csv.fail("column 'phase' is empty");
    if (phase == "Prepara\xC3\xA7\xC3\xA3o") phase = "Preparation";  // one Portuguese label in b1_raw.csv
    rec.frame_labels.push_back(phase);
    add_wrists(rec, wrist(12), wrist(15));
    rec.frames.push_back(std::move(s));
  });
  return rec;
}

// ---- skelgraph generic CSV ----

constexpr const char* kGenericMagic = "# skelgraph skeleton csv v1";
const std::array<const char*, 8> kJointFields = {"x", "y", "z", "qw", "qx", "qy", "qz", "conf"};

Recording read_generic(const std::string& path, const ReadOptions& opt) {
  auto rec = empty_recording(Format::Generic, path);
  // Metadata comments come first; CsvReader sees them as one-field lines.
  CsvReader csv(path);
  std::vector<std::string> f;
  if (!csv.next(f) || f.size() != 1 || f[0] != kGenericMagic) {
    csv.fail(std::string("expected the first line to be '") + kGenericMagic + "'");
  }
  std::vector<std::string> header;
  while (csv.next(f)) {
    if (!f.empty() && f[0].rfind("#", 0) == 0) {
      std::string line = f[0];  // a value may hold commas
      for (std::size_t i = 1; i < f.size(); ++i) line += "," + f[i];
      const auto colon = line.find(':');
      if (colon == std::string::npos) csv.fail("expected a metadata line '# key: value'");
      auto key = line.substr(1, colon - 1);
      auto value = line.substr(colon + 1);
      key.erase(0, key.find_first_not_of(' '));
      value.erase(0, value.find_first_not_of(' '));
      rec.metadata[key] = value;
      continue;
    }
    header = f;
    break;
  }
  if (header.empty()) csv.fail("no header line");
  // Column positions by name; every column must be known.
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (!col.emplace(header[i], i).second) csv.fail("column '" + header[i] + "' appears twice");
  }
  const std::vector<std::string> required_base = {"stamp_ns", "sensor_id", "person_id"};
  std::vector<std::string> known = {"stamp_ns", "sensor_id", "person_id", "frame_id", "frame_number"};
  for (std::size_t j = 0; j < kJointCount; ++j) {
    for (const auto* suffix : kJointFields) known.push_back(std::string(skeleton::joint_name(skeleton::joint_at(j))) + "_" + suffix);
  }
  // Joints beyond the canonical 15: extra_<name>_x/_y/_z (empty: not reported).
  std::map<std::string, std::array<std::size_t, 3>> extra_cols;
  for (const auto& h : header) {
    if (std::find(known.begin(), known.end(), h) != known.end()) continue;
    static const std::regex extra("extra_([a-z0-9_]+)_([xyz])");
    std::smatch m;
    if (!std::regex_match(h, m, extra)) csv.fail("unknown column '" + h + "'");
    auto [it, fresh] = extra_cols.try_emplace(m[1].str(), std::array<std::size_t, 3>{SIZE_MAX, SIZE_MAX, SIZE_MAX});
    it->second[static_cast<std::size_t>(m[2].str()[0] - 'x')] = col[h];
  }
  for (const auto& [name, c] : extra_cols) {
    for (std::size_t k = 0; k < 3; ++k)
      if (c[k] == SIZE_MAX) csv.fail("missing column 'extra_" + name + "_" + std::string(1, static_cast<char>('x' + k)) + "'");
  }
  for (const auto& r : required_base) {
    if (!col.count(r)) csv.fail("missing column '" + r + "'");
  }
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const std::string n = skeleton::joint_name(skeleton::joint_at(j));
    for (const auto* s : {"x", "y", "z", "conf"}) {
      if (!col.count(n + "_" + s)) csv.fail("missing column '" + n + "_" + s + "'");
    }
  }
  const auto opt_col = [&](const std::string& name) -> std::optional<std::size_t> {
    const auto it = col.find(name);
    return it == col.end() ? std::nullopt : std::optional<std::size_t>(it->second);
  };
  read_rows(csv, opt, rec, [&](const std::vector<std::string>& row) {
    expect_fields(csv, row, header.size(), "one per header column");
    skeleton::Skeleton s;
    s.stamp_ns = csv.integer(row, col["stamp_ns"], "stamp_ns");
    s.sensor_id = opt.sensor_id.empty() ? row[col["sensor_id"]] : opt.sensor_id;
    const auto person = csv.integer(row, col["person_id"], "person_id");
    if (person < 0 || person > 0xffffffffLL) csv.fail("person_id expects 0..4294967295, got " + row[col["person_id"]]);
    s.person_id = static_cast<std::uint32_t>(person);
    if (auto c = opt_col("frame_id")) s.frame_id = row[*c];
    if (auto c = opt_col("frame_number")) s.frame_number = static_cast<std::uint64_t>(csv.integer(row, *c, "frame_number"));
    for (std::size_t j = 0; j < kJointCount; ++j) {
      const std::string n = skeleton::joint_name(skeleton::joint_at(j));
      auto& joint = s.joints[j];
      joint.position = {csv.number(row, col[n + "_x"], n + "_x"), csv.number(row, col[n + "_y"], n + "_y"),
                        csv.number(row, col[n + "_z"], n + "_z")};
      if (auto qw = opt_col(n + "_qw")) {
        joint.orientation = Eigen::Quaterniond(csv.number(row, *qw, n + "_qw"), csv.number(row, col[n + "_qx"], n + "_qx"),
                                               csv.number(row, col[n + "_qy"], n + "_qy"), csv.number(row, col[n + "_qz"], n + "_qz"));
      }
      const double conf = csv.number(row, col[n + "_conf"], n + "_conf");
      if (conf < 0.0 || conf > 1.0) csv.fail(n + "_conf expects a confidence in [0, 1], got " + row[col[n + "_conf"]]);
      joint.confidence = static_cast<float>(conf);
    }
    for (const auto& [name, c] : extra_cols) {
      Eigen::Vector3d p;
      for (std::size_t k = 0; k < 3; ++k) {
        const std::string column = "extra_" + name + "_" + std::string(1, static_cast<char>('x' + k));
        p[static_cast<Eigen::Index>(k)] = row[c[k]].empty() ? std::nan("") : csv.number(row, c[k], column);
      }
      rec.extra_joints[name].push_back(p);
    }
    rec.frames.push_back(std::move(s));
  });
  return rec;
}

}  // namespace

namespace {
Recording read_any(Format format, const std::string& path, const ReadOptions& options) {
  switch (format) {
    case Format::Generic: return read_generic(path, options);
    case Format::KinderGator: return read_kinder_gator(path, options);
    case Format::KinectV2: return read_kinect_v2(path, options);
    case Format::MultiTrack: return read_multitrack(path, options);
    case Format::GesturePhase: return read_gesture_phase(path, options);
    case Format::Msrc12: return read_msrc12(path, options);
  }
  throw std::invalid_argument("unknown format");
}
}  // namespace

Recording read_recording(Format format, const std::string& path, const ReadOptions& options) {
  auto rec = read_any(format, path, options);
  if (rec.frames.empty()) {
    const auto& r = rec.report;
    throw DataError(path, r.last_line,
                    r.lines == 0 ? std::string("no data rows: expected skeleton frames after the header")
                    : r.skipped == r.lines
                        ? "no skeleton frames: every one of the " + std::to_string(r.lines) + " data rows was bad (first: " +
                              (r.problems.empty() ? std::string("?") : r.problems.front()) + ")"
                        : "no skeleton frames in " + std::to_string(r.lines) + " data rows (nobody tracked)");
  }
  return rec;
}

std::vector<Annotation> read_tagstream(const std::string& path) {
  CsvReader csv(path, ';');
  std::vector<std::string> f;
  if (!csv.next(f)) csv.fail("empty file; expected the header 'XQPCTick;Tag'");
  if (f.size() != 2 || f[0] != "XQPCTick" || f[1] != "Tag") csv.fail("expected the header 'XQPCTick;Tag'");
  std::vector<Annotation> out;
  while (csv.next(f)) {
    if (f.size() != 2 || f[1].empty()) csv.fail("expected '<tick>;<gesture name>', got " + std::to_string(f.size()) + " fields");
    const auto tick = csv.integer(f, 0, "XQPCTick");
    if (tick < 0) csv.fail("a negative tick");
    const std::int64_t us = (tick * 1000 + 49875 / 2) / 49875;
    if (!out.empty() && us * 1000 < out.back().start_ns) csv.fail("ticks go backwards");
    out.push_back({f[1], us * 1000, us * 1000});
  }
  return out;
}

std::vector<Annotation> read_annotation_csv(const std::string& path, const Recording& rec) {
  CsvReader csv(path);
  std::vector<std::string> f;
  if (!csv.next(f)) csv.fail("empty file; expected a header 'label,start_s,end_s' or 'label,start_frame,end_frame'");
  const bool seconds = f == std::vector<std::string>{"label", "start_s", "end_s"};
  const bool frames = f == std::vector<std::string>{"label", "start_frame", "end_frame"};
  if (!seconds && !frames) csv.fail("expected a header 'label,start_s,end_s' or 'label,start_frame,end_frame'");
  if (rec.frames.empty()) csv.fail("the recording it annotates has no frames");
  const auto t0 = rec.frames.front().stamp_ns;
  std::vector<Annotation> out;
  while (csv.next(f)) {
    expect_fields(csv, f, 3, seconds ? "label, start_s, end_s" : "label, start_frame, end_frame");
    if (f[0].empty()) csv.fail("an empty label");
    Annotation a;
    a.label = f[0];
    if (seconds) {
      a.start_ns = t0 + static_cast<std::int64_t>(std::llround(csv.number(f, 1, "start_s") * 1e9));
      a.end_ns = t0 + static_cast<std::int64_t>(std::llround(csv.number(f, 2, "end_s") * 1e9));
    } else {
      const auto frame = [&](std::size_t i, const char* column) {
        const auto k = csv.integer(f, i, column);
        if (k < 0 || static_cast<std::size_t>(k) >= rec.frames.size())
          csv.fail(std::string(column) + " " + std::to_string(k) + " is outside the recording's " +
                   std::to_string(rec.frames.size()) + " frames");
        return rec.frames[static_cast<std::size_t>(k)].stamp_ns;
      };
      a.start_ns = frame(1, "start_frame");
      a.end_ns = frame(2, "end_frame");
    }
    if (a.end_ns < a.start_ns) csv.fail("the annotation ends before it starts");
    out.push_back(std::move(a));
  }
  std::stable_sort(out.begin(), out.end(), [](const Annotation& a, const Annotation& b) { return a.start_ns < b.start_ns; });
  return out;
}

std::vector<Annotation> annotations_from_frame_labels(const Recording& rec, const std::vector<std::string>& rest) {
  std::vector<Annotation> out;
  const auto n = std::min(rec.frame_labels.size(), rec.frames.size());
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && rec.frame_labels[j + 1] == rec.frame_labels[i]) ++j;
    if (std::find(rest.begin(), rest.end(), rec.frame_labels[i]) == rest.end())
      out.push_back({rec.frame_labels[i], rec.frames[i].stamp_ns, rec.frames[j].stamp_ns});
    i = j + 1;
  }
  return out;
}

std::vector<Annotation> annotations_of(const Recording& rec) {
  const auto beside = fs::path(rec.source).replace_extension(".annotations.csv");
  if (fs::exists(beside)) return read_annotation_csv(beside.string(), rec);
  if (!rec.annotations.empty()) return rec.annotations;
  return annotations_from_frame_labels(rec);
}

std::string skipped_summary(const Recording& rec) {
  const auto& r = rec.report;
  if (r.skipped == 0) return {};
  return printable(rec.source + ": " + std::to_string(r.skipped) + " bad line" + (r.skipped == 1 ? "" : "s") + " of " +
                   std::to_string(r.lines) + " skipped (first: " + (r.problems.empty() ? std::string("?") : r.problems.front()) +
                   ")");
}

void write_generic_csv(const Recording& rec, std::ostream& out) {
  out << kGenericMagic << "\n";
  for (const auto& [k, v] : rec.metadata) {
    if (k.find_first_of(":\r\n") != std::string::npos || v.find_first_of("\r\n") != std::string::npos) {
      throw std::invalid_argument("generic CSV: metadata '" + k + "' has a line break (or a colon in its key)");
    }
    out << "# " << k << ": " << v << "\n";
  }
  out << "stamp_ns,sensor_id,person_id,frame_id,frame_number";
  for (std::size_t j = 0; j < kJointCount; ++j) {
    for (const auto* suffix : kJointFields) out << "," << skeleton::joint_name(skeleton::joint_at(j)) << "_" << suffix;
  }
  for (const auto& [name, points] : rec.extra_joints) {
    if (points.size() != rec.frames.size())
      throw std::invalid_argument("generic CSV: extra joint '" + name + "' has " + std::to_string(points.size()) + " positions for " +
                                  std::to_string(rec.frames.size()) + " frames");
    if (!std::regex_match(name, std::regex("[a-z0-9_]+"))) throw std::invalid_argument("generic CSV: extra joint name '" + name + "'");
    for (const char* axis : {"x", "y", "z"}) out << ",extra_" << name << "_" << axis;
  }
  out << "\n" << std::setprecision(17);
  for (const auto& s : rec.frames) {
    for (const auto* id : {&s.sensor_id, &s.frame_id}) {
      if (id->find_first_of(",\r\n") != std::string::npos) {
        throw std::invalid_argument("generic CSV: id '" + *id + "' contains a comma or line break");
      }
    }
    out << s.stamp_ns << "," << s.sensor_id << "," << s.person_id << "," << s.frame_id << "," << s.frame_number;
    for (const auto& j : s.joints) {
      out << "," << j.position.x() << "," << j.position.y() << "," << j.position.z() << "," << j.orientation.w() << ","
          << j.orientation.x() << "," << j.orientation.y() << "," << j.orientation.z() << "," << j.confidence;
    }
    const auto frame = static_cast<std::size_t>(&s - rec.frames.data());
    for (const auto& [name, points] : rec.extra_joints) {
      for (Eigen::Index k = 0; k < 3; ++k) {
        out << ",";
        if (std::isfinite(points[frame][k])) out << points[frame][k];  // empty: not reported
      }
    }
    out << "\n";
  }
}

}  // namespace skelgraph::playback
