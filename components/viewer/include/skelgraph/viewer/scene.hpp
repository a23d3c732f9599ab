#pragma once
// What the browser viewer shows, kept from the samples that arrive and turned
// into one JSON "frame" message per broadcast (docs in components/viewer/README.md).
// Pure: no DDS, no sockets, time passed in.
//
// Skeletons: the latest of each stream (a sensor's raw skeleton, the fused one,
// ground truth) and person, in the world frame: a raw skeleton is placed with
// its sensor's pose; one whose sensor has no pose yet is counted, not drawn.
// Joints keep their tracking state: 2 tracked, 1 inferred, 0 lost (not drawn).

#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/rate_stats.hpp"
#include "skelgraph/skeleton/skeleton.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::viewer {

enum class StreamKind { Raw, Fused, Truth };
const char* kind_name(StreamKind k);
// "fused" and "truth" by their sensor_id on the wire; everything else is a sensor.
StreamKind stream_kind(const std::string& sensor_id);

// 2 tracked (confidence >= 0.75), 1 inferred (> 0), 0 lost.
int joint_state(float confidence);

struct SceneOptions {
  std::int64_t max_age_ns = 500'000'000;       // skeletons older than this are not drawn
  std::int64_t gesture_hold_ns = 3'000'000'000;  // a gesture event stays on screen this long
  std::int64_t status_max_age_ns = 5'000'000'000;
  std::int64_t rate_window_ns = 2'000'000'000;
  double fov_h_deg = 57.0, fov_v_deg = 43.0;   // sensors' view frustums
  double near_m = 0.8, far_m = 4.0;
};

class Scene {
 public:
  explicit Scene(SceneOptions options = {});

  void on_skeleton(const skeleton::Skeleton& s, std::int64_t now_ns);
  // The stream's writer disposed this person (they left): no longer drawn.
  void on_gone(const std::string& sensor_id, std::uint32_t person_id);
  // A pose in a frame other than "world" is ignored (returns false).
  bool on_pose(const skeleton::SensorPose& p);
  // Any JSON object (the adapter converts GestureEvent, ComponentStatus, PlayState).
  void on_gesture(nlohmann::json event, std::int64_t now_ns);
  void on_status(const std::string& component, nlohmann::json status, std::int64_t now_ns);
  void on_player(const std::string& player, nlohmann::json state);
  // A robot's state and its monitor's verdict (the adapter converts
  // RobotState and SafetyStatus; keyed by robot_id). A robot not heard of
  // for status_max_age_ns is no longer drawn.
  void on_robot(nlohmann::json state, std::int64_t now_ns);
  void on_safety(nlohmann::json status, std::int64_t now_ns);

  // The frame message: {"type":"frame", "seq", "skeletons": [...], "sensors": [...],
  // (each skeleton's joints [x, y, z, state, radius_95], m; state 0: not drawn)
  // "streams": {...}, "gestures": [...], "status": [...], "players": [...], "unplaced": [...],
  // "robots": [{"id", "capsules": [[ax, ay, az, bx, by, bz, radius], ...], "tool": [x, y, z] (m, to the mm),
  //   "speed_scale", "stopped", "safety": the verdict (state, separation_m, protective_m, person_id,
  //   body_part, robot_part, reason) or null}]}.
  // Drops what has aged out as of now_ns.
  nlohmann::json frame(std::int64_t now_ns);

  std::size_t skeletons_held() const { return skeletons_.size(); }

 private:
  struct Held {
    skeleton::Skeleton world;  // in the world frame
    StreamKind kind;
    std::int64_t received_ns;
  };
  struct Stream {
    StreamKind kind;
    runtime::RateStats rate;
    std::uint64_t unplaced = 0;  // raw samples dropped for want of a pose
  };
  SceneOptions o_;
  std::uint64_t seq_ = 0;
  std::map<std::tuple<std::string, std::uint32_t>, Held> skeletons_;  // (stream, person)
  std::map<std::string, Stream> streams_;
  std::map<std::string, skeleton::SensorPose> poses_;
  std::vector<std::pair<std::int64_t, nlohmann::json>> gestures_;
  std::map<std::string, std::pair<std::int64_t, nlohmann::json>> robots_, safety_;  // by robot_id: (received, message)
  std::map<std::string, std::pair<std::int64_t, nlohmann::json>> status_;
  std::map<std::string, nlohmann::json> players_;
};

}  // namespace skelgraph::viewer
