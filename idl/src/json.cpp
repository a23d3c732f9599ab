#include "skelgraph/msg/json.hpp"

#include <algorithm>
#include <array>

namespace skelgraph::msg {

namespace {
const char* const kJointNames[JOINT_COUNT] = {
    "head",      "neck",      "torso",     "left_shoulder", "left_elbow",
    "left_hand", "right_shoulder", "right_elbow", "right_hand", "left_hip",
    "left_knee", "left_foot", "right_hip", "right_knee",    "right_foot"};
}  // namespace

const char* joint_name(JointId id) {
  const auto i = static_cast<std::uint32_t>(id);
  return i < JOINT_COUNT ? kJointNames[i] : "unknown";
}

const char* to_string(SyncKind k) {
  switch (k) {
    case SYNC_START: return "START";
    case SYNC_STOP: return "STOP";
    case SYNC_TICK: return "TICK";
  }
  return "UNKNOWN";
}

const char* to_string(ComponentState s) {
  switch (s) {
    case STATE_OK: return "OK";
    case STATE_DEGRADED: return "DEGRADED";
    case STATE_ERROR: return "ERROR";
  }
  return "UNKNOWN";
}

const char* to_string(PlayKind k) {
  switch (k) {
    case PLAY_PAUSE: return "PAUSE";
    case PLAY_RESUME: return "RESUME";
    case PLAY_STEP: return "STEP";
    case PLAY_SPEED: return "SPEED";
    case PLAY_SEEK: return "SEEK";
  }
  return "UNKNOWN";
}

void to_json(nlohmann::json& j, const Vec3& v) { j = {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}}; }
void to_json(nlohmann::json& j, const Quat& q) {
  j = {{"w", q.w()}, {"x", q.x()}, {"y", q.y()}, {"z", q.z()}};
}
void to_json(nlohmann::json& j, const Joint& v) {
  j = {{"position", v.position()},
       {"orientation", v.orientation()},
       {"confidence", v.confidence()},
       {"sensor_mask", v.sensor_mask()}};
}
void to_json(nlohmann::json& j, const Skeleton& v) {
  nlohmann::json joints = nlohmann::json::array();
  for (std::uint32_t i = 0; i < JOINT_COUNT; ++i) {
    nlohmann::json jj = v.joints()[i];
    jj["name"] = kJointNames[i];
    joints.push_back(std::move(jj));
  }
  j = {{"sensor_id", v.sensor_id()},     {"person_id", v.person_id()},
       {"frame_id", v.frame_id()},       {"stamp_ns", v.stamp_ns()},
       {"frame_number", v.frame_number()}, {"joints", std::move(joints)},
       {"capture_oldest_ns", v.capture_oldest_ns()}, {"capture_newest_ns", v.capture_newest_ns()}};
  nlohmann::json cov = nlohmann::json::array();
  for (const auto& c : v.covariance())
    cov.push_back({{"xx", c.xx()}, {"xy", c.xy()}, {"xz", c.xz()}, {"yy", c.yy()}, {"yz", c.yz()}, {"zz", c.zz()}});
  j["covariance"] = std::move(cov);
}
void to_json(nlohmann::json& j, const SyncCommand& v) {
  j = {{"kind", to_string(v.kind())}, {"session_id", v.session_id()}, {"label", v.label()},
       {"tick", v.tick()},            {"master_stamp_ns", v.master_stamp_ns()},
       {"request_id", v.request_id()}};
}
void to_json(nlohmann::json& j, const SyncControl& v) {
  j = {{"kind", to_string(v.kind())}, {"label", v.label()}, {"requester", v.requester()},
       {"request_id", v.request_id()}};
}
void to_json(nlohmann::json& j, const ClockOffset& v) {
  j = {{"host", v.host().to_string()},   {"session_id", v.session_id()}, {"offset_ns", v.offset_ns()},
       {"drift_ppm", v.drift_ppm()},     {"rtt_ns", v.rtt_ns()},         {"samples", v.samples()},
       {"stamp_ns", v.stamp_ns()}};
}
void to_json(nlohmann::json& j, const FrameRef& v) {
  j = {{"topic", v.topic().to_string()},   {"host", v.host().to_string()},
       {"sensor_id", v.sensor_id().to_string()}, {"person_id", v.person_id()},
       {"frame_number", v.frame_number()}, {"stamp_ns", v.stamp_ns()},
       {"log_time_ns", v.log_time_ns()}};
}
void to_json(nlohmann::json& j, const SensorFrame& v) {
  j = {{"sensor_id", v.sensor_id().to_string()}, {"stamp_ns", v.stamp_ns()}, {"frame_number", v.frame_number()},
       {"people", v.people()}};
}
void to_json(nlohmann::json& j, const TickFrames& v) {
  j = {{"session_id", v.session_id()}, {"tick", v.tick()}, {"master_stamp_ns", v.master_stamp_ns()},
       {"frames", v.frames()}};
}

void to_json(nlohmann::json& j, const SyncAck& v) {
  j = {{"component_name", v.component_name()}, {"host", v.host()},
       {"session_id", v.session_id()},         {"tick", v.tick()},
       {"master_stamp_ns", v.master_stamp_ns()}, {"receive_stamp_ns", v.receive_stamp_ns()},
       {"send_stamp_ns", v.send_stamp_ns()}};
}
void to_json(nlohmann::json& j, const SensorPose& v) {
  j = {{"sensor_id", v.sensor_id()},       {"frame_id", v.frame_id()},
       {"translation", v.translation()},   {"rotation", v.rotation()},
       {"stamp_ns", v.stamp_ns()},         {"method", v.method()},
       {"rms_residual_m", v.rms_residual_m()}, {"max_residual_m", v.max_residual_m()}};
}
void to_json(nlohmann::json& j, const CameraIntrinsics& v) {
  j = {{"fx", v.fx()}, {"fy", v.fy()}, {"cx", v.cx()}, {"cy", v.cy()}};
}
void to_json(nlohmann::json& j, const DepthFrame& v) {
  // The image itself is summarised: a JSON array of 300k numbers helps nobody.
  std::uint64_t valid = 0;
  for (auto d : v.depth_mm()) valid += d != 0 ? 1 : 0;
  j = {{"sensor_id", v.sensor_id()}, {"stamp_ns", v.stamp_ns()},
       {"frame_number", v.frame_number()}, {"width", v.width()},
       {"height", v.height()},       {"intrinsics", v.intrinsics()},
       {"depth_mm_count", v.depth_mm().size()}, {"depth_mm_valid", valid}};
}
void to_json(nlohmann::json& j, const GestureEvent& v) {
  j = {{"label", v.label()},           {"person_id", v.person_id()},
       {"source", v.source()},         {"start_stamp_ns", v.start_stamp_ns()},
       {"end_stamp_ns", v.end_stamp_ns()}, {"score", v.score()},
       {"log_likelihood", v.log_likelihood()}, {"confidence", v.confidence()},
       {"arm", v.arm()},               {"has_ray", v.has_ray()},
       {"has_target", v.has_target()}, {"ray_origin", v.ray_origin()},
       {"ray_direction", v.ray_direction()}, {"target", v.target()},
       {"target_name", v.target_name()}};
}
void to_json(nlohmann::json& j, const GestureState& v) {
  j = {{"person_id", v.person_id()}, {"source", v.source()}, {"stamp_ns", v.stamp_ns()}, {"state", v.state()}};
}
void to_json(nlohmann::json& j, const PointCloud& v) {
  // Summarised like depth images: the count and the bounds, not every point.
  const auto& p = v.xyz();
  nlohmann::json lo = nullptr, hi = nullptr;
  if (p.size() >= 3) {
    std::array<float, 3> a{p[0], p[1], p[2]}, b = a;
    for (std::size_t i = 0; i + 2 < p.size(); i += 3) {
      for (std::size_t k = 0; k < 3; ++k) {
        a[k] = std::min(a[k], p[i + k]);
        b[k] = std::max(b[k], p[i + k]);
      }
    }
    lo = a;
    hi = b;
  }
  j = {{"source", v.source()}, {"frame_id", v.frame_id()}, {"stamp_ns", v.stamp_ns()},
       {"frame_number", v.frame_number()}, {"voxel_m", v.voxel_m()}, {"points", p.size() / 3},
       {"min", lo}, {"max", hi}};
}
void to_json(nlohmann::json& j, const TopicStats& v) {
  j = {{"topic", v.topic()}, {"is_output", v.is_output()}, {"count", v.count()},
       {"rate_hz", v.rate_hz()}, {"dropped", v.dropped()}, {"instances", v.instances()}};
}
void to_json(nlohmann::json& j, const ComponentStatus& v) {
  j = {{"component_name", v.component_name()}, {"kind", v.kind()},
       {"host", v.host()},                     {"stamp_ns", v.stamp_ns()},
       {"state", to_string(v.state())},        {"message", v.message()},
       {"topics", v.topics()}};
}

void to_json(nlohmann::json& j, const PlayControl& v) {
  j = {{"target", v.target().to_string()}, {"kind", to_string(v.kind())}, {"value", v.value()},
       {"request_id", v.request_id().to_string()}};
}
void to_json(nlohmann::json& j, const PlayState& v) {
  j = {{"player", v.player().to_string()}, {"paused", v.paused()},     {"speed", v.speed()},
       {"frames", v.frames()},             {"frame_count", v.frame_count()}, {"at_end", v.at_end()},
       {"request_id", v.request_id().to_string()}, {"error", v.error().to_string()},
       {"position_s", v.position_s()}, {"duration_s", v.duration_s()}};
}

const char* to_string(RobotCommandKind k) {
  switch (k) {
    case ROBOT_MOVE_TO: return "MOVE_TO";
    case ROBOT_HOLD: return "HOLD";
    case ROBOT_SPEED_SCALE: return "SPEED_SCALE";
    case ROBOT_PROTECTIVE_STOP: return "PROTECTIVE_STOP";
    case ROBOT_RESUME: return "RESUME";
  }
  return "UNKNOWN";
}

const char* to_string(SafetyStateKind k) {
  switch (k) {
    case SAFETY_RUN: return "RUN";
    case SAFETY_REDUCED: return "REDUCED";
    case SAFETY_PROTECTIVE_STOP: return "PROTECTIVE_STOP";
  }
  return "UNKNOWN";
}

void to_json(nlohmann::json& j, const Capsule& v) {
  j = {{"a", v.a()}, {"b", v.b()}, {"radius", v.radius()}, {"name", v.name().to_string()}};
}

void to_json(nlohmann::json& j, const RobotState& v) {
  j = {{"robot_id", v.robot_id().to_string()},
       {"model", v.model().to_string()},
       {"stamp_ns", v.stamp_ns()},
       {"joints", v.joints()},
       {"joint_speeds", v.joint_speeds()},
       {"tool_position", v.tool_position()},
       {"tool_speed", v.tool_speed()},
       {"speed_scale", v.speed_scale()},
       {"protective_stop", v.protective_stop()},
       {"has_target", v.has_target()},
       {"target", v.target()},
       {"capsules", v.capsules()}};
}

void to_json(nlohmann::json& j, const RobotCommand& v) {
  j = {{"robot_id", v.robot_id().to_string()}, {"kind", to_string(v.kind())}, {"target", v.target()},
       {"value", v.value()}, {"source", v.source().to_string()}, {"stamp_ns", v.stamp_ns()}};
}

void to_json(nlohmann::json& j, const SafetyStatus& v) {
  j = {{"robot_id", v.robot_id().to_string()},     {"stamp_ns", v.stamp_ns()},
       {"state", to_string(v.state())},            {"speed_scale", v.speed_scale()},
       {"separation_m", v.separation_m()},         {"protective_m", v.protective_m()},
       {"person_id", v.person_id()},               {"body_part", v.body_part().to_string()},
       {"robot_part", v.robot_part().to_string()}, {"people_age_ms", v.people_age_ms()},
       {"reaction_ms", v.reaction_ms()},           {"reason", v.reason().to_string()}};
}

}  // namespace skelgraph::msg
