#include "skelgraph/calib/calib_file.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace skelgraph::calib {

namespace {

[[noreturn]] void fail(const std::string& path, const YAML::Node& n, const std::string& what) {
  const auto m = n.Mark();
  throw CalibFileError(path + (m.is_null() ? "" : ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1)) +
                       ": " + what);
}

std::vector<double> numbers(const std::string& path, const YAML::Node& n, const char* key, std::size_t count) {
  const auto v = n[key];
  if (!v) fail(path, n, std::string("missing '") + key + "'");
  if (!v.IsSequence() || v.size() != count) fail(path, v, std::string("'") + key + "' expects a list of " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (const auto& x : v) {
    double d = 0;
    try {
      d = x.as<double>();
    } catch (const YAML::Exception&) {
      fail(path, x, std::string("'") + key + "' expects numbers, got '" + x.as<std::string>("?") + "'");
    }
    if (!std::isfinite(d)) fail(path, x, std::string("'") + key + "' expects finite numbers");
    out.push_back(d);
  }
  return out;
}

// The file parsed, or CalibFileError naming file:line:column.
YAML::Node load(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw CalibFileError(path + ": cannot read the file");
  } catch (const YAML::ParserException& e) {
    throw CalibFileError(path + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

// `translation` (m) and `rotation_xyzw` (a unit quaternion) of a mapping.
Eigen::Isometry3d pose_at(const std::string& path, const YAML::Node& n) {
  const auto t = numbers(path, n, "translation", 3);
  const auto q = numbers(path, n, "rotation_xyzw", 4);
  Eigen::Quaterniond quat(q[3], q[0], q[1], q[2]);
  if (std::abs(quat.norm() - 1.0) > 1e-3) fail(path, n["rotation_xyzw"], "'rotation_xyzw' is not a unit quaternion (norm " + std::to_string(quat.norm()) + ")");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = quat.normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return pose;
}

void emit_pose(YAML::Emitter& e, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  const Eigen::Vector3d t = pose.translation();
  e << YAML::Key << "translation" << YAML::Value << YAML::Flow << std::vector<double>{t.x(), t.y(), t.z()};
  e << YAML::Key << "rotation_xyzw" << YAML::Value << YAML::Flow << std::vector<double>{q.x(), q.y(), q.z(), q.w()};
}

// The emitted document, after a first-line comment.
void save(const std::string& path, const YAML::Emitter& e, const std::string& comment) {
  std::ofstream out(path);
  if (!comment.empty()) out << "# " << comment << "\n";
  out << e.c_str() << "\n";
  if (!out.flush()) throw CalibFileError(path + ": cannot write the file");
}

}  // namespace

CalibFile read_calib_file(const std::string& path) {
  const YAML::Node root = load(path);
  if (!root.IsMap()) fail(path, root, "expected a mapping with 'version', 'frame_id' and 'sensors'");
  if (!root["version"] || root["version"].as<std::string>("") != "1") {
    fail(path, root["version"] ? root["version"] : root, "expected 'version: 1'");
  }
  CalibFile f;
  if (root["frame_id"]) f.frame_id = root["frame_id"].as<std::string>();
  const auto sensors = root["sensors"];
  if (!sensors || !sensors.IsSequence() || sensors.size() == 0) fail(path, sensors ? sensors : root, "expected 'sensors': a non-empty list");
  for (const auto& s : sensors) {
    if (!s.IsMap() || !s["id"]) fail(path, s, "each sensor needs an 'id'");
    skeleton::SensorPose p;
    p.sensor_id = s["id"].as<std::string>();
    p.frame_id = f.frame_id;
    p.pose = pose_at(path, s);
    p.method = s["method"] ? s["method"].as<std::string>() : "manual";
    p.rms_residual_m = s["rms_residual_m"] ? s["rms_residual_m"].as<double>() : 0.0;
    p.max_residual_m = s["max_residual_m"] ? s["max_residual_m"].as<double>() : 0.0;
    for (const auto& other : f.sensors) {
      if (other.sensor_id == p.sensor_id) fail(path, s["id"], "sensor '" + p.sensor_id + "' is listed twice");
    }
    f.sensors.push_back(std::move(p));
  }
  return f;
}

void write_calib_file(const std::string& path, const CalibFile& f) {
  YAML::Emitter e;
  e.SetDoublePrecision(9);
  e << YAML::BeginMap << YAML::Key << "version" << YAML::Value << 1 << YAML::Key << "frame_id" << YAML::Value
    << f.frame_id << YAML::Key << "sensors" << YAML::Value << YAML::BeginSeq;
  for (const auto& p : f.sensors) {
    e << YAML::BeginMap << YAML::Key << "id" << YAML::Value << p.sensor_id;
    emit_pose(e, p.pose);
    e << YAML::Key << "method" << YAML::Value << p.method;
    e << YAML::Key << "rms_residual_m" << YAML::Value << p.rms_residual_m;
    e << YAML::Key << "max_residual_m" << YAML::Value << p.max_residual_m << YAML::EndMap;
  }
  e << YAML::EndSeq << YAML::EndMap;
  save(path, e, f.comment);
}

namespace {
std::vector<Eigen::Vector3d> points(const std::string& path, const YAML::Node& parent, const char* key) {
  const auto n = parent[key];
  if (!n || !n.IsSequence() || n.size() < 3) fail(path, n ? n : parent, std::string("'") + key + "' expects a list of at least 3 [x, y, z] points");
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : n) {
    if (!p.IsSequence() || p.size() != 3) fail(path, p, std::string("'") + key + "' expects [x, y, z] points");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      try {
        v[i] = p[i].as<double>();
      } catch (const YAML::Exception&) {
        fail(path, p[i], std::string("'") + key + "' expects numbers");
      }
    }
    out.push_back(v);
  }
  return out;
}
}  // namespace

BoardMarkers read_board_markers(const std::string& path) {
  const YAML::Node root = load(path);
  if (!root.IsMap() || !root["version"] || root["version"].as<std::string>("") != "1") {
    fail(path, root, "expected a board markers file with 'version: 1'");
  }
  BoardMarkers m;
  m.in_board = points(path, root, "markers_in_board");
  const auto views = root["views"];
  if (!views || !views.IsSequence()) fail(path, root, "expected 'views': a list of {name, markers_in_world}");
  for (const auto& v : views) {
    if (!v.IsMap() || !v["name"]) fail(path, v, "each view needs a 'name'");
    auto w = points(path, v, "markers_in_world");
    if (w.size() != m.in_board.size()) {
      fail(path, v["markers_in_world"], std::to_string(w.size()) + " markers, but markers_in_board lists " + std::to_string(m.in_board.size()));
    }
    m.in_world[v["name"].as<std::string>()] = std::move(w);
  }
  return m;
}

void write_board_markers(const std::string& path, const BoardMarkers& m, const std::string& comment) {
  const auto seq = [](YAML::Emitter& e, const std::vector<Eigen::Vector3d>& pts) {
    e << YAML::BeginSeq;
    for (const auto& p : pts) e << YAML::Flow << std::vector<double>{p.x(), p.y(), p.z()};
    e << YAML::EndSeq;
  };
  YAML::Emitter e;
  e.SetDoublePrecision(9);
  e << YAML::BeginMap << YAML::Key << "version" << YAML::Value << 1 << YAML::Key << "markers_in_board" << YAML::Value;
  seq(e, m.in_board);
  e << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (const auto& [name, pts] : m.in_world) {
    e << YAML::BeginMap << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << name << YAML::Key
      << "markers_in_world" << YAML::Value;
    seq(e, pts);
    e << YAML::EndMap;
  }
  e << YAML::EndSeq << YAML::EndMap;
  save(path, e, comment);
}

Intrinsics read_intrinsics_file(const std::string& path) {
  const YAML::Node root = load(path);
  if (!root.IsMap() || !root["version"] || root["version"].as<std::string>("") != "1") {
    fail(path, root, "expected an intrinsics file with 'version: 1'");
  }
  Intrinsics k;
  const auto number = [&](const char* key) {
    if (!root[key]) fail(path, root, std::string("missing '") + key + "'");
    try {
      return root[key].as<double>();
    } catch (const YAML::Exception&) {
      fail(path, root[key], std::string("'") + key + "' expects a number");
    }
  };
  k.width = static_cast<int>(number("width"));
  k.height = static_cast<int>(number("height"));
  k.fx = number("fx");
  k.fy = number("fy");
  k.cx = number("cx");
  k.cy = number("cy");
  if (!(k.fx > 0 && k.fy > 0 && k.width > 0 && k.height > 0)) fail(path, root, "fx, fy, width and height must be > 0");
  if (root["distortion"]) {
    const auto n = root["distortion"].size();
    if (n != 0 && n != 4 && n != 5 && n != 8) fail(path, root["distortion"], "'distortion' expects 0, 4, 5 or 8 numbers");
    k.distortion = numbers(path, root, "distortion", n);
  }
  return k;
}

void write_intrinsics_file(const std::string& path, const Intrinsics& k, double rms_reprojection_px, std::size_t views,
                           const std::string& comment) {
  YAML::Emitter e;
  e.SetDoublePrecision(9);
  e << YAML::BeginMap << YAML::Key << "version" << YAML::Value << 1;
  e << YAML::Key << "width" << YAML::Value << k.width << YAML::Key << "height" << YAML::Value << k.height;
  e << YAML::Key << "fx" << YAML::Value << k.fx << YAML::Key << "fy" << YAML::Value << k.fy;
  e << YAML::Key << "cx" << YAML::Value << k.cx << YAML::Key << "cy" << YAML::Value << k.cy;
  e << YAML::Key << "distortion" << YAML::Value << YAML::Flow << k.distortion;
  e << YAML::Key << "rms_reprojection_px" << YAML::Value << rms_reprojection_px;
  e << YAML::Key << "views" << YAML::Value << views << YAML::EndMap;
  save(path, e, comment);
}

ToolPoses read_tool_poses(const std::string& path) {
  const YAML::Node root = load(path);
  if (!root.IsMap() || !root["version"] || root["version"].as<std::string>("") != "1") {
    fail(path, root, "expected a tool poses file with 'version: 1'");
  }
  ToolPoses t;
  t.robot = root["robot"] ? root["robot"].as<std::string>() : "";
  if (!root["board_on_tool"] || !root["board_on_tool"].IsMap()) {
    fail(path, root, "expected 'board_on_tool': {translation, rotation_xyzw}, the board's pose in the tool frame");
  }
  t.tool_from_board = pose_at(path, root["board_on_tool"]);
  const auto views = root["views"];
  if (!views || !views.IsSequence() || views.size() == 0) {
    fail(path, views ? views : root, "expected 'views': a list of {name, translation, rotation_xyzw}, the tool in the base frame");
  }
  for (const auto& v : views) {
    if (!v.IsMap() || !v["name"]) fail(path, v, "each view needs a 'name'");
    const auto name = v["name"].as<std::string>();
    if (t.base_from_tool.count(name)) fail(path, v["name"], "view '" + name + "' is listed twice");
    t.base_from_tool[name] = pose_at(path, v);
  }
  return t;
}

void write_tool_poses(const std::string& path, const ToolPoses& t, const std::string& comment) {
  YAML::Emitter e;
  e.SetDoublePrecision(9);
  e << YAML::BeginMap << YAML::Key << "version" << YAML::Value << 1 << YAML::Key << "robot" << YAML::Value << t.robot;
  e << YAML::Key << "board_on_tool" << YAML::Value << YAML::BeginMap;
  emit_pose(e, t.tool_from_board);
  e << YAML::EndMap << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (const auto& [name, pose] : t.base_from_tool) {
    e << YAML::BeginMap << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << name;
    emit_pose(e, pose);
    e << YAML::EndMap;
  }
  e << YAML::EndSeq << YAML::EndMap;
  save(path, e, comment);
}

Eigen::Isometry3d read_transform_file(const std::string& path, const std::string& sensor_id) {
  YAML::Node y;
  try {
    y = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw CalibFileError(path + ": not a readable YAML file: " + e.msg);
  }
  if (y["sensors"]) {
    const auto c = read_calib_file(path);
    std::string ids;
    for (const auto& s : c.sensors) {
      if (s.sensor_id == sensor_id) return s.pose;
      ids += (ids.empty() ? "" : ", ") + s.sensor_id;
    }
    throw CalibFileError(path + ": no sensor '" + sensor_id + "' (the motion-capture system's pose; --mocap-id) among " + ids);
  }
  const auto r = y["rotation"], t = y["translation"];
  if (!r || !r.IsSequence() || r.size() != 9 || !t || !t.IsSequence() || t.size() != 3)
    throw CalibFileError(path + ": expected rotation: [9 numbers, row-major] and translation: [x, y, z] (metres)");
  Eigen::Matrix3d m;
  try {
    for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = r[static_cast<std::size_t>(i)].as<double>();
  } catch (const YAML::Exception& e) {
    throw CalibFileError(path + ": rotation: " + e.msg);
  }
  if (!(m * m.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || m.determinant() < 0)
    throw CalibFileError(path + ": the rotation is not a rotation (orthonormal, determinant 1)");
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = m;
  try {
    iso.translation() = Eigen::Vector3d(t[0].as<double>(), t[1].as<double>(), t[2].as<double>());
  } catch (const YAML::Exception& e) {
    throw CalibFileError(path + ": translation: " + e.msg);
  }
  return iso;
}

}  // namespace skelgraph::calib
