#pragma once
// JSON views of the wire types, for `topic echo --json`, logs and tests.
// Enums are written by name; joints as an array in JointId order.

#include <nlohmann/json.hpp>

#include "skelgraph/msg/messages.hpp"

// Bounded IDL strings (fixed_string<N>) appear in JSON as plain strings.
namespace nlohmann {
template <std::size_t N>
struct adl_serializer<eprosima::fastrtps::fixed_string<N>> {
  static void to_json(json& j, const eprosima::fastrtps::fixed_string<N>& s) { j = s.to_string(); }
};
}  // namespace nlohmann

namespace skelgraph::msg {

void to_json(nlohmann::json& j, const Vec3& v);
void to_json(nlohmann::json& j, const Quat& q);
void to_json(nlohmann::json& j, const Joint& v);
void to_json(nlohmann::json& j, const Skeleton& v);
void to_json(nlohmann::json& j, const SyncCommand& v);
void to_json(nlohmann::json& j, const SyncControl& v);
void to_json(nlohmann::json& j, const SyncAck& v);
void to_json(nlohmann::json& j, const ClockOffset& v);
void to_json(nlohmann::json& j, const FrameRef& v);
void to_json(nlohmann::json& j, const TickFrames& v);
void to_json(nlohmann::json& j, const SensorFrame& v);
void to_json(nlohmann::json& j, const SensorPose& v);
void to_json(nlohmann::json& j, const CameraIntrinsics& v);
void to_json(nlohmann::json& j, const DepthFrame& v);
void to_json(nlohmann::json& j, const GestureEvent& v);
void to_json(nlohmann::json& j, const GestureState& v);
void to_json(nlohmann::json& j, const PointCloud& v);
void to_json(nlohmann::json& j, const PlayControl& v);
void to_json(nlohmann::json& j, const PlayState& v);
void to_json(nlohmann::json& j, const TopicStats& v);
void to_json(nlohmann::json& j, const ComponentStatus& v);
void to_json(nlohmann::json& j, const Capsule& v);
void to_json(nlohmann::json& j, const RobotState& v);
void to_json(nlohmann::json& j, const RobotCommand& v);
void to_json(nlohmann::json& j, const SafetyStatus& v);

const char* to_string(SyncKind k);
const char* to_string(ComponentState s);
const char* to_string(PlayKind k);
const char* to_string(RobotCommandKind k);  // "MOVE_TO", "HOLD", ...
const char* to_string(SafetyStateKind k);   // "RUN", "REDUCED", "PROTECTIVE_STOP"

}  // namespace skelgraph::msg
