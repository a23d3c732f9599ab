#include "skelgraph/playback/bvh.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace skelgraph::playback {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Whitespace-separated tokens with their line numbers.
class Tokens {
 public:
  explicit Tokens(const std::string& path) : path_(path), in_(path) {
    if (!in_) throw DataError(path, 0, "cannot open file");
  }
  bool next(std::string& t) {
    while (!(line_stream_ >> t)) {
      std::string line;
      if (!std::getline(in_, line)) return false;
      ++line_;
      line_stream_.clear();
      line_stream_.str(line);
    }
    return true;
  }
  std::string expect(const char* what) {
    std::string t;
    if (!next(t)) fail(std::string("the file ends; expected ") + what);
    return t;
  }
  double number(const char* what) {
    const auto t = expect(what);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size() || !std::isfinite(v)) fail(std::string("expected ") + what + " (a finite number), got '" + t + "'");
    return v;
  }
  // The rest of the current line, for the MOTION section's numbers.
  bool line(std::string& out) {
    std::string rest;
    std::getline(line_stream_, rest);
    line_stream_.clear();
    line_stream_.str("");
    if (rest.find_first_not_of(" \t\r") != std::string::npos) {
      out = rest;
      return true;
    }
    if (!std::getline(in_, out)) return false;
    ++line_;
    return true;
  }
  [[noreturn]] void fail(const std::string& what) const { throw DataError(path_, line_, what); }
  std::size_t line_number() const { return line_; }

 private:
  std::string path_;
  std::ifstream in_;
  std::istringstream line_stream_;
  std::size_t line_ = 0;
};

void read_joint(Tokens& t, Bvh& b, int parent, const std::string& name, bool end_site) {
  BvhJoint j;
  j.name = name;
  j.parent = parent;
  j.end_site = end_site;
  if (t.expect("'{'") != "{") t.fail("expected '{' after " + (end_site ? std::string("End Site") : "JOINT " + name));
  if (t.expect("OFFSET") != "OFFSET") t.fail("expected OFFSET in " + name);
  j.offset = {t.number("an OFFSET x"), t.number("an OFFSET y"), t.number("an OFFSET z")};
  const int index = static_cast<int>(b.joints.size());
  std::string tok = t.expect("CHANNELS, JOINT, End Site or '}'");
  if (tok == "CHANNELS") {
    if (end_site) t.fail("an End Site has no CHANNELS");
    const double n = t.number("the channel count");
    if (n < 0 || n > 6 || n != std::floor(n)) t.fail("expected a channel count of 0 to 6");
    for (int k = 0; k < static_cast<int>(n); ++k) {
      const auto c = t.expect("a channel name");
      static const std::vector<std::string> known{"Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"};
      if (std::find(known.begin(), known.end(), c) == known.end())
        t.fail("unknown channel '" + c + "' (expected X/Y/Z position or rotation)");
      j.channels.push_back(c);
    }
    tok = t.expect("JOINT, End Site or '}'");
  }
  j.first_channel = b.channel_count;
  b.channel_count += j.channels.size();
  b.joints.push_back(j);
  while (tok != "}") {
    if (tok == "JOINT") {
      read_joint(t, b, index, t.expect("a joint name"), false);
    } else if (tok == "End") {
      if (t.expect("Site") != "Site") t.fail("expected 'End Site'");
      read_joint(t, b, index, name + "_end", true);
    } else {
      t.fail("expected JOINT, End Site or '}', got '" + tok + "'");
    }
    tok = t.expect("'}'");
  }
}

Eigen::Matrix3d axis(char c, double deg) {
  const Eigen::Vector3d a = c == 'X' ? Eigen::Vector3d::UnitX() : c == 'Y' ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  return Eigen::AngleAxisd(deg * kPi / 180.0, a).toRotationMatrix();
}

}  // namespace

int Bvh::index_of(const std::string& name) const {
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == name && !joints[i].end_site) return static_cast<int>(i);
  return -1;
}

std::vector<Eigen::Vector3d> Bvh::positions(std::size_t f) const {
  const auto& v = frames.at(f);
  std::vector<Eigen::Isometry3d> global(joints.size());
  std::vector<Eigen::Vector3d> out(joints.size());
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto& j = joints[i];
    Eigen::Vector3d t = j.offset;
    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    for (std::size_t k = 0; k < j.channels.size(); ++k) {
      const auto& c = j.channels[k];
      const double x = v[j.first_channel + k];
      if (c[1] == 'p') t[c[0] - 'X'] += x;  // Xposition: 'X', 'p'
      else r = r * axis(c[0], x);
    }
    Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
    local.translation() = t;
    local.linear() = r;
    global[i] = j.parent < 0 ? local : global[static_cast<std::size_t>(j.parent)] * local;
    out[i] = global[i].translation();
  }
  return out;
}

Bvh read_bvh(const std::string& path) {
  Tokens t(path);
  Bvh b;
  if (t.expect("HIERARCHY") != "HIERARCHY") t.fail("expected HIERARCHY at the start of a BVH file");
  if (t.expect("ROOT") != "ROOT") t.fail("expected ROOT");
  read_joint(t, b, -1, t.expect("the root's name"), false);
  if (t.expect("MOTION") != "MOTION") t.fail("expected MOTION after the hierarchy (one ROOT only)");
  if (t.expect("Frames:") != "Frames:") t.fail("expected 'Frames:'");
  const double n = t.number("the frame count");
  if (n < 0 || n != std::floor(n)) t.fail("expected a whole frame count");
  if (t.expect("Frame") != "Frame" || t.expect("Time:") != "Time:") t.fail("expected 'Frame Time:'");
  b.frame_time_s = t.number("the frame time");
  if (!(b.frame_time_s > 0)) t.fail("expected a frame time > 0 s");
  std::string line;
  while (t.line(line)) {
    std::istringstream ls(line);
    std::vector<double> v;
    std::string tok;
    while (ls >> tok) {
      char* end = nullptr;
      const double x = std::strtod(tok.c_str(), &end);
      if (end != tok.c_str() + tok.size() || !std::isfinite(x)) t.fail("expected a finite number, got '" + tok + "'");
      v.push_back(x);
    }
    if (v.empty()) continue;
    if (v.size() != b.channel_count)
      t.fail(std::to_string(v.size()) + " values; the hierarchy has " + std::to_string(b.channel_count) + " channels");
    b.frames.push_back(std::move(v));
  }
  if (b.frames.size() != static_cast<std::size_t>(n))
    t.fail(std::to_string(b.frames.size()) + " frames; the header says " + std::to_string(static_cast<long long>(n)));
  return b;
}

const std::map<std::string, std::vector<std::string>>& default_bvh_mapping() {
  static const std::map<std::string, std::vector<std::string>> m{
      {"head", {"Head", "head", "mixamorig:Head"}},
      {"neck", {"Neck", "Neck1", "neck", "mixamorig:Neck", "SpineShoulder"}},
      {"torso", {"Spine1", "Spine", "Chest", "spine", "mixamorig:Spine1", "SpineMid"}},
      {"left_shoulder", {"LeftArm", "LeftUpperArm", "LeftShoulder", "mixamorig:LeftArm", "ShoulderLeft", "lShldr"}},
      {"left_elbow", {"LeftForeArm", "LeftLowerArm", "LeftElbow", "mixamorig:LeftForeArm", "ElbowLeft", "lForeArm"}},
      {"left_hand", {"LeftHand", "mixamorig:LeftHand", "HandLeft", "lHand"}},
      {"right_shoulder", {"RightArm", "RightUpperArm", "RightShoulder", "mixamorig:RightArm", "ShoulderRight", "rShldr"}},
      {"right_elbow", {"RightForeArm", "RightLowerArm", "RightElbow", "mixamorig:RightForeArm", "ElbowRight", "rForeArm"}},
      {"right_hand", {"RightHand", "mixamorig:RightHand", "HandRight", "rHand"}},
      {"left_hip", {"LeftUpLeg", "LeftThigh", "LeftHip", "mixamorig:LeftUpLeg", "HipLeft", "lThigh"}},
      {"left_knee", {"LeftLeg", "LeftShin", "LeftKnee", "mixamorig:LeftLeg", "KneeLeft", "lShin"}},
      {"left_foot", {"LeftFoot", "mixamorig:LeftFoot", "FootLeft", "lFoot"}},
      {"right_hip", {"RightUpLeg", "RightThigh", "RightHip", "mixamorig:RightUpLeg", "HipRight", "rThigh"}},
      {"right_knee", {"RightLeg", "RightShin", "RightKnee", "mixamorig:RightLeg", "KneeRight", "rShin"}},
      {"right_foot", {"RightFoot", "mixamorig:RightFoot", "FootRight", "rFoot"}}};
  return m;
}

std::vector<std::pair<std::size_t, double>> read_bvh_time_points(const std::string& path) {
  CsvReader csv(path);
  std::vector<std::string> f;
  if (!csv.next(f) || f != std::vector<std::string>{"mocap_frame", "time_s"}) csv.fail("expected the header 'mocap_frame,time_s'");
  std::vector<std::pair<std::size_t, double>> out;
  while (csv.next(f)) {
    if (f.size() != 2) csv.fail("expected 2 fields (mocap_frame, time_s), got " + std::to_string(f.size()));
    const auto frame = csv.integer(f, 0, "mocap_frame");
    if (frame < 0) csv.fail("mocap_frame must not be negative");
    out.emplace_back(static_cast<std::size_t>(frame), csv.number(f, 1, "time_s"));
  }
  if (out.empty()) csv.fail("no matched moments");
  return out;
}

std::map<std::string, std::string> read_bvh_mapping(const std::string& path) {
  YAML::Node y;
  try {
    y = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw DataError(path, 0, "cannot open file");
  } catch (const YAML::Exception& e) {
    throw DataError(path, static_cast<std::size_t>(e.mark.line + 1), "not YAML: " + e.msg);
  }
  const auto j = y["joints"];
  if (!j || !j.IsMap()) throw DataError(path, 1, "expected 'joints:' mapping canonical joint names to the BVH's");
  std::map<std::string, std::string> m;
  for (const auto& kv : j) {
    const auto key = kv.first.as<std::string>();
    if (!default_bvh_mapping().count(key))
      throw DataError(path, static_cast<std::size_t>(kv.first.Mark().line + 1), "'" + key + "' is not a canonical joint");
    m[key] = kv.second.as<std::string>();
  }
  return m;
}

Recording bvh_recording(const std::string& path, const Bvh& bvh, const BvhOptions& o) {
  Recording rec;
  rec.format = "bvh";
  rec.source = path;
  std::array<int, skeleton::kJointCount> index{};
  std::string names;
  for (const auto& j : bvh.joints)
    if (!j.end_site) names += (names.empty() ? "" : ", ") + j.name;
  for (std::size_t k = 0; k < skeleton::kJointCount; ++k) {
    const std::string canonical = skeleton::joint_name(skeleton::joint_at(k));
    int found = -1;
    if (const auto it = o.joints.find(canonical); it != o.joints.end()) {
      found = bvh.index_of(it->second);
      if (found < 0) throw DataError(path, 0, "the mapping's '" + it->second + "' (for " + canonical + ") is not a joint of this file (" + names + ")");
    } else {
      for (const auto& c : default_bvh_mapping().at(canonical))
        if ((found = bvh.index_of(c)) >= 0) break;
      if (found < 0)
        throw DataError(path, 0, "no joint for " + canonical + " among this file's (" + names +
                                     "); give a mapping file (joints: {" + canonical + ": NAME})");
    }
    index[k] = found;
  }
  // Frame f's time: t0 + rate * f.
  double t0 = o.time_offset_s, rate = bvh.frame_time_s;
  if (o.time_points.size() == 1) {
    t0 = o.time_points[0].second - static_cast<double>(o.time_points[0].first) * bvh.frame_time_s;
  } else if (o.time_points.size() > 1) {
    double mf = 0, mt = 0;
    for (const auto& [f, t] : o.time_points) {
      mf += static_cast<double>(f);
      mt += t;
    }
    mf /= static_cast<double>(o.time_points.size());
    mt /= static_cast<double>(o.time_points.size());
    double sff = 0, sft = 0;
    for (const auto& [f, t] : o.time_points) {
      sff += (static_cast<double>(f) - mf) * (static_cast<double>(f) - mf);
      sft += (static_cast<double>(f) - mf) * (t - mt);
    }
    if (!(sff > 0)) throw DataError(path, 0, "the matched moments name one mocap frame only");
    rate = sft / sff;
    if (!(rate > 0)) throw DataError(path, 0, "the matched moments put later mocap frames earlier");
    t0 = mt - rate * mf;
  }
  for (std::size_t f = 0; f < bvh.frames.size(); ++f) {
    const auto p = bvh.positions(f);
    skeleton::Skeleton s;
    s.sensor_id = o.sensor_id;
    s.frame_id = o.frame_id;
    s.person_id = 1;
    s.frame_number = f;
    s.stamp_ns = static_cast<std::int64_t>(std::llround((t0 + rate * static_cast<double>(f)) * 1e9));
    for (std::size_t k = 0; k < skeleton::kJointCount; ++k) {
      s.joints[k].position = o.target_from_mocap * (o.units_to_m * p[static_cast<std::size_t>(index[k])]);
      s.joints[k].confidence = skeleton::kTracked;
    }
    rec.frames.push_back(std::move(s));
  }
  rec.metadata["frame_time_s"] = std::to_string(bvh.frame_time_s);
  rec.metadata["joints"] = names;
  return rec;
}

void write_position_bvh(const std::vector<skeleton::Skeleton>& frames, double frame_time_s, double units_per_m, std::ostream& out) {
  using skeleton::JointId;
  // Parent of each canonical joint (torso the root); names as the default mapping's first candidates.
  const std::vector<std::pair<JointId, int>> order{
      {JointId::Torso, -1},       {JointId::Neck, 0},          {JointId::Head, 1},         {JointId::LeftShoulder, 1},
      {JointId::LeftElbow, 3},    {JointId::LeftHand, 4},      {JointId::RightShoulder, 1}, {JointId::RightElbow, 6},
      {JointId::RightHand, 7},    {JointId::LeftHip, 0},       {JointId::LeftKnee, 9},     {JointId::LeftFoot, 10},
      {JointId::RightHip, 0},     {JointId::RightKnee, 12},    {JointId::RightFoot, 13}};
  const auto bvh_name = [](JointId j) { return default_bvh_mapping().at(skeleton::joint_name(j)).front(); };
  out << "HIERARCHY\n";
  // Depth-first with explicit closing braces: children follow their parent in `order`.
  std::vector<int> open;
  for (std::size_t i = 0; i < order.size(); ++i) {
    while (!open.empty() && open.back() != order[i].second) {
      out << std::string(2 * (open.size() - 1), ' ') << "}\n";
      open.pop_back();
    }
    const std::string indent(2 * open.size(), ' ');
    out << indent << (i == 0 ? "ROOT " : "JOINT ") << bvh_name(order[i].first) << "\n" << indent << "{\n"
        << indent << "  OFFSET 0 0 0\n" << indent << "  CHANNELS 3 Xposition Yposition Zposition\n";
    open.push_back(static_cast<int>(i));
  }
  while (!open.empty()) {
    out << std::string(2 * (open.size() - 1), ' ') << "}\n";
    open.pop_back();
  }
  out << "MOTION\nFrames: " << frames.size() << "\nFrame Time: " << std::setprecision(17) << frame_time_s << "\n";
  for (const auto& s : frames) {
    for (std::size_t i = 0; i < order.size(); ++i) {
      const auto& p = s[order[i].first].position;
      const Eigen::Vector3d local = order[i].second < 0 ? p : p - s[order[static_cast<std::size_t>(order[i].second)].first].position;
      out << (i ? " " : "") << local.x() * units_per_m << " " << local.y() * units_per_m << " " << local.z() * units_per_m;
    }
    out << "\n";
  }
}

}  // namespace skelgraph::playback
