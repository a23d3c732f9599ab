#pragma once
// The cell as a 3-D scene for Foxglove and Lichtblick: what a recording holds
// (skeletons of every stream, the sensors' poses, pointing events, the
// robot's capsules) turned into foxglove::SceneUpdate messages, one per tick,
// and foxglove::FrameTransform messages for the frames. Items go in in log
// time order; time comes from them (no clock). No DDS.
//
// Frames: `world` (ours: metres, y up) sits in `cell`, the same place with z
// up (Foxglove's convention: choose `cell` as the display frame and people
// stand upright); each sensor's frame (its id) in `world` by its pose. Raw
// skeletons are drawn in their sensor's frame, fused and true ones in
// `world`. A frame with no pose in the recording (a data set's camera space)
// is placed at the world's origin (unplaced()).
// Entities: one per stream, sensor and person ("raw/sensor1/3",
// "fused/fusion/1", "truth/sim/2"): joints as spheres (tracked opaque,
// inferred translucent, lost left out), bones as a line list, a colour per
// stream; a frustum per sensor; a pointing event's ray and target; the
// robot's capsules, coloured by the separation monitor's verdict, and that
// verdict as a label. Each has a lifetime, so a person who left disappears.
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "skelgraph/scene/foxglove.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::scene {

struct SceneOptions {
  double tick_s = 1.0 / 30;        // one SceneUpdate per tick with what changed in it
  double lifetime_s = 0.5;         // a skeleton not renewed this long disappears
  double event_lifetime_s = 3.0;   // a pointing ray and target stay this long
  double joint_diameter_m = 0.06;
  double bone_thickness_m = 0.02;
  double frustum_depth_m = 1.0;    // how far the sensors' view pyramids reach
  double frustum_h_deg = 57.0;     // their field of view (a Kinect's)
  double frustum_v_deg = 43.0;
  double transforms_every_s = 1.0; // the poses again, so a viewer that seeks has them
};

enum class Stream { Raw, Fused, Truth };
const char* stream_name(Stream s);  // "raw", "fused", "truth"

// The bones drawn between the canonical joints.
const std::vector<std::pair<skeleton::JointId, skeleton::JointId>>& bones();

struct Pointing {  // a pointing event (skelgraph/gesture/event), world frame
  std::uint32_t person_id = 0;
  std::string label, arm;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), direction = Eigen::Vector3d::UnitZ();
  bool has_target = false;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double confidence = 0;
};

enum class SafetyState { Run, Reduced, ProtectiveStop };

struct Safety {  // speed-and-separation monitoring's verdict (skelgraph/safety)
  std::string robot_id;
  SafetyState state = SafetyState::Run;
  double speed_scale = 1.0;
  double separation_m = -1.0;  // -1: nobody
  std::uint32_t person_id = 0;
  std::string body_part, reason;
};

struct Capsule {  // world frame
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0.05;
  std::string name;
};

// What the builder gives out, in log-time order.
struct Output {
  std::int64_t log_ns = 0;
  bool is_transform = false;
  SceneUpdate update;        // !is_transform
  FrameTransform transform;  // is_transform
};

class SceneBuilder {
 public:
  explicit SceneBuilder(SceneOptions options = {});
  void add_skeleton(Stream stream, const skeleton::Skeleton& s, std::int64_t log_ns);
  void add_pose(const skeleton::SensorPose& pose, std::int64_t log_ns);
  void add_pointing(const Pointing& p, std::int64_t log_ns);
  void add_robot(const std::string& robot_id, const std::vector<Capsule>& capsules, bool stopped, std::int64_t log_ns);
  // The robot's colour follows it (green run, amber reduced, red stop) and a
  // label above its base says why ("safety/<robot>").
  void add_safety(const Safety& s, std::int64_t log_ns);
  // Everything decided before log_ns (ticks that ended); then finish() for the rest.
  std::vector<Output> take(std::int64_t log_ns);
  std::vector<Output> finish();
  const SceneOptions& options() const { return o_; }
  // Frames skeletons were in that had no pose: drawn at the world's origin.
  const std::set<std::string>& unplaced() const { return unplaced_; }

 private:
  void advance(std::int64_t log_ns);
  void flush_tick();
  void put(Entity e);
  Color sensor_color(const std::string& sensor_id);
  std::vector<FrameTransform> transforms(std::int64_t stamp_ns) const;

  SceneOptions o_;
  std::int64_t tick_ns_;
  std::int64_t tick_end_ = -1;                 // the open tick's end (-1: none open)
  std::map<std::string, Entity> pending_;      // by id: the latest of each in the open tick
  std::map<std::string, skeleton::SensorPose> poses_;
  std::set<std::string> unplaced_;
  std::map<std::string, SafetyState> safety_;         // by robot: the latest verdict
  std::map<std::string, Eigen::Vector3d> robot_base_;  // by robot: where its first capsule starts
  std::map<std::string, int> sensor_index_;    // colours in order of appearance
  std::int64_t transforms_at_ = -1;            // when the poses were last given out
  std::vector<Output> out_;
};

}  // namespace skelgraph::scene
