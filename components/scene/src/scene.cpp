#include "skelgraph/scene/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace skelgraph::scene {

namespace {

using skeleton::JointId;

constexpr double kPi = 3.14159265358979323846;

std::int64_t ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

Eigen::Quaterniond along(const Eigen::Vector3d& axis, const Eigen::Vector3d& direction) {
  if (direction.norm() < 1e-12) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond::FromTwoVectors(axis, direction.normalized());
}

const Color kFused{0.15, 0.85, 0.25, 1.0};
const Color kTruth{0.92, 0.92, 0.92, 1.0};
const std::array<Color, 6> kSensorColors{{{0.25, 0.55, 1.0, 1.0},
                                          {1.0, 0.55, 0.1, 1.0},
                                          {0.8, 0.3, 0.9, 1.0},
                                          {1.0, 0.85, 0.1, 1.0},
                                          {0.1, 0.8, 0.8, 1.0},
                                          {0.95, 0.3, 0.3, 1.0}}};

}  // namespace

const char* stream_name(Stream s) {
  switch (s) {
    case Stream::Raw: return "raw";
    case Stream::Fused: return "fused";
    case Stream::Truth: return "truth";
  }
  return "?";
}

const std::vector<std::pair<JointId, JointId>>& bones() {
  static const std::vector<std::pair<JointId, JointId>> b{
      {JointId::Head, JointId::Neck},          {JointId::Neck, JointId::Torso},
      {JointId::Neck, JointId::LeftShoulder},  {JointId::LeftShoulder, JointId::LeftElbow},
      {JointId::LeftElbow, JointId::LeftHand}, {JointId::Neck, JointId::RightShoulder},
      {JointId::RightShoulder, JointId::RightElbow}, {JointId::RightElbow, JointId::RightHand},
      {JointId::Torso, JointId::LeftHip},      {JointId::LeftHip, JointId::LeftKnee},
      {JointId::LeftKnee, JointId::LeftFoot},  {JointId::Torso, JointId::RightHip},
      {JointId::RightHip, JointId::RightKnee}, {JointId::RightKnee, JointId::RightFoot},
      {JointId::LeftHip, JointId::RightHip}};
  return b;
}

SceneBuilder::SceneBuilder(SceneOptions options) : o_(options), tick_ns_(std::max<std::int64_t>(1, ns(options.tick_s))) {}

Color SceneBuilder::sensor_color(const std::string& sensor_id) {
  const auto it = sensor_index_.try_emplace(sensor_id, static_cast<int>(sensor_index_.size())).first;
  return kSensorColors[static_cast<std::size_t>(it->second) % kSensorColors.size()];
}

void SceneBuilder::put(Entity e) { pending_[e.id] = std::move(e); }

void SceneBuilder::flush_tick() {
  if (!pending_.empty()) {
    Output o;
    o.log_ns = tick_end_ - 1;
    for (auto& [id, e] : pending_) {
      o.log_ns = std::max(o.log_ns, e.stamp_ns);
      o.update.entities.push_back(std::move(e));
    }
    o.log_ns = std::min(o.log_ns, tick_end_ - 1);
    out_.push_back(std::move(o));
    pending_.clear();
  }
  tick_end_ = -1;
}

std::vector<FrameTransform> SceneBuilder::transforms(std::int64_t stamp_ns) const {
  std::vector<FrameTransform> t;
  FrameTransform up;  // world (y up) in cell (z up): a quarter turn about x
  up.stamp_ns = stamp_ns;
  up.parent = "cell";
  up.child = "world";
  up.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()));
  t.push_back(up);
  for (const auto& [id, p] : poses_) {
    FrameTransform f;
    f.stamp_ns = stamp_ns;
    f.parent = p.frame_id.empty() ? "world" : p.frame_id;
    f.child = id;
    f.translation = p.pose.translation();
    f.rotation = Eigen::Quaterniond(p.pose.rotation());
    t.push_back(f);
  }
  for (const auto& id : unplaced_) {
    if (poses_.count(id)) continue;
    FrameTransform f;
    f.stamp_ns = stamp_ns;
    f.parent = "world";
    f.child = id;
    t.push_back(f);
  }
  return t;
}

void SceneBuilder::advance(std::int64_t log_ns) {
  if (tick_end_ >= 0 && log_ns >= tick_end_) flush_tick();
  if (transforms_at_ < 0 || log_ns - transforms_at_ >= ns(o_.transforms_every_s)) {
    transforms_at_ = log_ns;
    for (auto& t : transforms(log_ns)) {
      Output o;
      o.log_ns = log_ns;
      o.is_transform = true;
      o.transform = std::move(t);
      out_.push_back(std::move(o));
    }
    // The frusta again with them (a viewer that seeks starts from here).
    for (const auto& [id, p] : poses_) {
      const double d = o_.frustum_depth_m, w = d * std::tan(o_.frustum_h_deg * kPi / 360),
                   h = d * std::tan(o_.frustum_v_deg * kPi / 360);
      Entity e;
      e.stamp_ns = log_ns;
      e.frame_id = id;
      e.id = "sensor/" + id;
      e.metadata = {{"sensor", id}};
      Line l;
      l.thickness = 0.01;
      l.color = sensor_color(id);
      const std::array<Eigen::Vector3d, 4> c{{{-w, -h, d}, {w, -h, d}, {w, h, d}, {-w, h, d}}};
      for (int k = 0; k < 4; ++k) {
        l.points.push_back(Eigen::Vector3d::Zero());
        l.points.push_back(c[static_cast<std::size_t>(k)]);
        l.points.push_back(c[static_cast<std::size_t>(k)]);
        l.points.push_back(c[static_cast<std::size_t>((k + 1) % 4)]);
      }
      e.lines.push_back(std::move(l));
      Text t;
      t.text = id;
      t.color = sensor_color(id);
      e.texts.push_back(std::move(t));
      put(std::move(e));
    }
  }
  if (tick_end_ < 0) tick_end_ = (log_ns / tick_ns_ + 1) * tick_ns_;
}

void SceneBuilder::add_skeleton(Stream stream, const skeleton::Skeleton& s, std::int64_t log_ns) {
  const std::string frame = !s.frame_id.empty() ? s.frame_id : stream == Stream::Raw ? s.sensor_id : "world";
  if (frame != "world" && !poses_.count(frame) && unplaced_.insert(frame).second) transforms_at_ = -1;
  advance(log_ns);
  Entity e;
  e.stamp_ns = log_ns;
  e.frame_id = frame;
  e.id = std::string(stream_name(stream)) + "/" + s.sensor_id + "/" + std::to_string(s.person_id);
  e.lifetime_ns = ns(o_.lifetime_s);
  e.metadata = {{"stream", stream_name(stream)}, {"sensor", s.sensor_id}, {"person", std::to_string(s.person_id)}};
  const Color base = stream == Stream::Fused ? kFused : stream == Stream::Truth ? kTruth : sensor_color(s.sensor_id);
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    const auto& joint = s.joints[j];
    if (joint.confidence <= skeleton::kLost) continue;
    Sphere sp;
    sp.pose.position = joint.position;
    sp.size = Eigen::Vector3d::Constant(o_.joint_diameter_m);
    sp.color = base;
    sp.color.a = joint.confidence >= skeleton::kTracked ? 1.0 : 0.35;  // inferred: translucent
    e.spheres.push_back(sp);
  }
  Line l;
  l.thickness = o_.bone_thickness_m;
  l.color = base;
  l.color.a = 0.8;
  for (const auto& [a, b] : bones()) {
    if (s[a].confidence <= skeleton::kLost || s[b].confidence <= skeleton::kLost) continue;
    l.points.push_back(s[a].position);
    l.points.push_back(s[b].position);
  }
  if (!l.points.empty()) e.lines.push_back(std::move(l));
  put(std::move(e));
}

void SceneBuilder::add_pose(const skeleton::SensorPose& pose, std::int64_t log_ns) {
  const auto it = poses_.find(pose.sensor_id);
  const bool changed = it == poses_.end() || !it->second.pose.isApprox(pose.pose) || it->second.frame_id != pose.frame_id;
  poses_[pose.sensor_id] = pose;
  sensor_color(pose.sensor_id);
  if (changed) transforms_at_ = -1;  // given out (with the frusta) at once
  advance(log_ns);
}

void SceneBuilder::add_pointing(const Pointing& p, std::int64_t log_ns) {
  advance(log_ns);
  Entity e;
  e.stamp_ns = log_ns;
  e.frame_id = "world";
  e.id = "pointing/" + std::to_string(p.person_id);
  e.lifetime_ns = ns(o_.event_lifetime_s);
  e.metadata = {{"person", std::to_string(p.person_id)}, {"label", p.label}, {"arm", p.arm},
                {"confidence", std::to_string(p.confidence)}};
  const Color orange{1.0, 0.45, 0.0, 1.0};
  Arrow a;
  a.pose.position = p.origin;
  a.pose.orientation = along(Eigen::Vector3d::UnitX(), p.direction);
  const double length = p.has_target ? (p.target - p.origin).norm() : 1.5;
  a.head_length = std::min(0.15, 0.3 * length);
  a.shaft_length = std::max(0.0, length - a.head_length);
  a.shaft_diameter = 0.02;
  a.head_diameter = 0.06;
  a.color = orange;
  e.arrows.push_back(a);
  if (p.has_target) {
    Sphere t;
    t.pose.position = p.target;
    t.size = Eigen::Vector3d(0.2, 0.02, 0.2);  // a disc on the floor
    t.color = orange;
    e.spheres.push_back(t);
  }
  put(std::move(e));
}

void SceneBuilder::add_robot(const std::string& robot_id, const std::vector<Capsule>& capsules, bool stopped,
                             std::int64_t log_ns) {
  advance(log_ns);
  Entity e;
  e.stamp_ns = log_ns;
  e.frame_id = "world";
  e.id = "robot/" + robot_id;
  e.lifetime_ns = ns(o_.lifetime_s);
  e.metadata = {{"robot", robot_id}, {"protective_stop", stopped ? "true" : "false"}};
  const auto verdict = safety_.find(robot_id);
  const auto state = stopped ? SafetyState::ProtectiveStop : verdict == safety_.end() ? SafetyState::Run : verdict->second;
  const Color c = state == SafetyState::ProtectiveStop ? Color{0.9, 0.15, 0.1, 0.85}
                  : state == SafetyState::Reduced      ? Color{1.0, 0.7, 0.1, 0.85}
                  : verdict != safety_.end()           ? Color{0.2, 0.75, 0.3, 0.85}
                                                       : Color{0.6, 0.62, 0.66, 0.85};
  if (!capsules.empty()) robot_base_[robot_id] = capsules.front().a;
  for (const auto& k : capsules) {
    const Eigen::Vector3d axis = k.b - k.a;
    Cylinder y;
    y.pose.position = 0.5 * (k.a + k.b);
    y.pose.orientation = along(Eigen::Vector3d::UnitZ(), axis);
    y.size = Eigen::Vector3d(2 * k.radius, 2 * k.radius, axis.norm());
    y.color = c;
    if (axis.norm() > 1e-9) e.cylinders.push_back(y);
    for (const auto* end : {&k.a, &k.b}) {
      Sphere s;
      s.pose.position = *end;
      s.size = Eigen::Vector3d::Constant(2 * k.radius);
      s.color = c;
      e.spheres.push_back(s);
    }
  }
  put(std::move(e));
}

void SceneBuilder::add_safety(const Safety& s, std::int64_t log_ns) {
  advance(log_ns);
  safety_[s.robot_id] = s.state;
  Entity e;
  e.stamp_ns = log_ns;
  e.frame_id = "world";
  e.id = "safety/" + s.robot_id;
  e.lifetime_ns = ns(o_.event_lifetime_s);
  const char* name = s.state == SafetyState::Run ? "run" : s.state == SafetyState::Reduced ? "reduced" : "protective stop";
  e.metadata = {{"robot", s.robot_id}, {"state", name}, {"speed_scale", std::to_string(s.speed_scale)},
                {"separation_m", std::to_string(s.separation_m)}, {"reason", s.reason}};
  Text t;
  const auto base = robot_base_.find(s.robot_id);
  t.pose.position = (base != robot_base_.end() ? base->second : Eigen::Vector3d::Zero()) + Eigen::Vector3d(0, 1.3, 0);
  t.font_size = 0.12;
  t.color = s.state == SafetyState::Run ? Color{0.2, 0.75, 0.3, 1} : s.state == SafetyState::Reduced ? Color{1.0, 0.7, 0.1, 1}
                                                                                                    : Color{0.9, 0.15, 0.1, 1};
  char text[160];
  if (s.separation_m >= 0)
    std::snprintf(text, sizeof text, "%s, speed %.0f %%: person %u's %s %.2f m away", name, 100 * s.speed_scale, s.person_id,
                  s.body_part.c_str(), s.separation_m);
  else
    std::snprintf(text, sizeof text, "%s, speed %.0f %%: nobody near", name, 100 * s.speed_scale);
  t.text = text;
  if (s.state != SafetyState::Run && !s.reason.empty()) t.text += "\n" + s.reason;
  e.texts.push_back(std::move(t));
  put(std::move(e));
}

std::vector<Output> SceneBuilder::take(std::int64_t log_ns) {
  if (tick_end_ >= 0 && log_ns >= tick_end_) flush_tick();
  auto out = std::move(out_);
  out_.clear();
  return out;
}

std::vector<Output> SceneBuilder::finish() {
  if (tick_end_ >= 0) flush_tick();
  auto out = std::move(out_);
  out_.clear();
  return out;
}

}  // namespace skelgraph::scene
