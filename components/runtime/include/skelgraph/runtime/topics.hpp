#pragma once
// Every topic name, its wire type and its QoS, in one place.

#include <string>
#include <vector>

#include "skelgraph/msg/messages.hpp"

namespace skelgraph::runtime {

enum class Reliability { BestEffort, Reliable };
enum class Durability { Volatile, TransientLocal };

// Every endpoint sets its resource limits from this, never Fast DDS's
// defaults (10 instances per writer and reader: the 10th person of a cell
// was refused). Keyed topics: at most `max_instances` instances alive at once
// in a writer or reader; writers dispose an instance when its person, sensor
// or component is gone, which frees it. Samples: `depth` per instance (keep
// last), or kKeepAllSamples per instance (keep all).
struct QosPreset {
  Reliability reliability = Reliability::Reliable;
  Durability durability = Durability::Volatile;
  int depth = 0;  // history depth per instance; 0 = keep all
  int max_instances = kDefaultInstances;  // keyed types only (an unkeyed topic is one instance)

  static constexpr int kDefaultInstances = 256;  // topics outside the table (tools reading foreign topics)
  static constexpr int kKeepAllSamples = 5000;   // per instance, keep-all topics (a reliable writer then blocks)
};

// A reader that only shows the newest samples (a display) asks for best
// effort on any topic: a reliable writer serves it as well, and nothing is
// repaired or queued for it.
inline QosPreset newest_only(QosPreset q) {
  q.reliability = Reliability::BestEffort;
  return q;
}

// A topic bound to its wire type at compile time.
template <class T>
struct TopicDef {
  const char* name;
  QosPreset qos;
};

namespace topics {

using R = Reliability;
using D = Durability;

// START / TICK / STOP as they happen (reliable, nothing dropped).
inline const TopicDef<msg::SyncCommand> kSync{"skelgraph/sync", {R::Reliable, D::Volatile, 0}};
// The latest START or STOP only, kept for late joiners (transient-local). A
// separate topic because keeping ticks for late joiners would replay them.
inline const TopicDef<msg::SyncCommand> kSyncSession{"skelgraph/sync/session", {R::Reliable, D::TransientLocal, 1}};
// Requests to the sync master (skelgraph sync start|stop, robots).
inline const TopicDef<msg::SyncControl> kSyncControl{"skelgraph/sync/control", {R::Reliable, D::Volatile, 0}};
inline const TopicDef<msg::SyncAck> kSyncAck{"skelgraph/sync_ack", {R::Reliable, D::Volatile, 0, 256}};
// Each host's clock offset, from the sync master; late joiners (recorders) get the latest per host.
inline const TopicDef<msg::ClockOffset> kSyncClock{"skelgraph/sync/clock", {R::Reliable, D::TransientLocal, 32, 64}};
inline const TopicDef<msg::Skeleton> kSkeletonRaw{"skelgraph/skeleton/raw", {R::BestEffort, D::Volatile, 5, 1024}};
// One per delivered sensor frame (people seen or not): the sensor is alive.
inline const TopicDef<msg::SensorFrame> kSensorFrame{"skelgraph/sensor/frame", {R::BestEffort, D::Volatile, 5, 64}};
inline const TopicDef<msg::Skeleton> kSkeletonFused{"skelgraph/skeleton/fused", {R::BestEffort, D::Volatile, 5, 256}};
inline const TopicDef<msg::Skeleton> kSkeletonTruth{"skelgraph/skeleton/truth", {R::Reliable, D::Volatile, 64, 256}};
inline const TopicDef<msg::DepthFrame> kDepth{"skelgraph/depth", {R::BestEffort, D::Volatile, 2, 64}};
// Keyed by sensor; the depth keeps every sensor's latest pose for readers
// that do not know the key (generic tools such as `topic echo`).
inline const TopicDef<msg::SensorPose> kCalibration{"skelgraph/calibration", {R::Reliable, D::TransientLocal, 32, 64}};
inline const TopicDef<msg::GestureEvent> kGestureEvent{"skelgraph/gesture/event", {R::Reliable, D::Volatile, 0}};
// Keyed by (source, person): the latest states of each person reach late
// joiners; disposed when the person leaves.
inline const TopicDef<msg::GestureState> kGestureState{"skelgraph/gesture/state", {R::Reliable, D::TransientLocal, 16, 256}};
// Thinned point clouds for viewers (the `cloud` component): the latest only.
inline const TopicDef<msg::PointCloud> kCloud{"skelgraph/cloud", {R::BestEffort, D::Volatile, 1, 64}};
// Requests to players of recordings (skelgraph play ...), and each player's
// state (keyed by player; late joiners get the latest).
inline const TopicDef<msg::PlayControl> kPlayControl{"skelgraph/play/control", {R::Reliable, D::Volatile, 0}};
inline const TopicDef<msg::PlayState> kPlayState{"skelgraph/play/state", {R::Reliable, D::TransientLocal, 16, 64}};
// The robot: its state at its control rate (the latest matters), requests to
// it (none lost), and the separation monitor's verdict per robot (none lost;
// the latest kept for late joiners).
inline const TopicDef<msg::RobotState> kRobotState{"skelgraph/robot/state", {R::BestEffort, D::Volatile, 1, 16}};
inline const TopicDef<msg::RobotCommand> kRobotCommand{"skelgraph/robot/command", {R::Reliable, D::Volatile, 0}};
inline const TopicDef<msg::SafetyStatus> kSafety{"skelgraph/safety", {R::Reliable, D::TransientLocal, 1, 16}};
inline const TopicDef<msg::ComponentStatus> kStatus{"skelgraph/status", {R::BestEffort, D::Volatile, 1, 256}};

}  // namespace topics

// The same table, untyped, for tools that start from a topic name.
struct TopicInfo {
  std::string name;
  std::string type_name;
  QosPreset qos;
};
const std::vector<TopicInfo>& known_topics();
const TopicInfo* find_topic(const std::string& name);

// How a tool that only reads (the recorder, `topic echo`, `topic hz`)
// subscribes to a topic of the table: its type, whether it is keyed, and its
// QoS with a deeper history, so that bursts are kept: a shorter history
// becomes `min_depth`; keep-all becomes `keep_all_depth` (writers never wait
// for this reader, which loses the oldest if it falls that far behind) or,
// with 0, stays keep-all (nothing lost; a writer waits once this reader holds
// QosPreset::kKeepAllSamples of an instance).
struct ReaderPlan {
  std::string type_name;
  bool keyed = false;
  QosPreset qos;
};
ReaderPlan reader_plan(const TopicInfo& topic, int min_depth, int keep_all_depth);

}  // namespace skelgraph::runtime
