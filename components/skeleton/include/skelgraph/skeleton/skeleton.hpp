#pragma once
// The canonical skeleton every core works on: 15 joints as NITE names them,
// Eigen types, no DDS. Sources map their own joint sets into this; the wire
// type (msg::Skeleton) is converted at the adapter boundary (skeleton_msg.hpp).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace skelgraph::skeleton {

// Same order as msg::JointId in idl/skelgraph.idl.
enum class JointId : std::uint8_t {
  Head,
  Neck,
  Torso,
  LeftShoulder,
  LeftElbow,
  LeftHand,
  RightShoulder,
  RightElbow,
  RightHand,
  LeftHip,
  LeftKnee,
  LeftFoot,
  RightHip,
  RightKnee,
  RightFoot
};
inline constexpr std::size_t kJointCount = 15;

// "head", "left_shoulder", ... (the names used in JSON, CSV headers and launch files).
const char* joint_name(JointId id);
std::optional<JointId> joint_from_name(std::string_view name);
inline constexpr JointId joint_at(std::size_t i) { return static_cast<JointId>(i); }

// Tracker confidence as NITE and the Kinect SDK report it.
inline constexpr float kTracked = 1.0f;
inline constexpr float kInferred = 0.5f;
inline constexpr float kLost = 0.0f;

struct Joint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();         // metres
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  float confidence = kLost;
  std::uint32_t sensor_mask = 0;  // fused output: which inputs contributed
  // Fused output: the position's uncertainty, the covariance's upper
  // triangle xx xy xz yy yz zz in m^2 (all 0: not given).
  std::array<float, 6> covariance{};
};

// A joint's covariance as a matrix, and set from one (upper triangle kept).
Eigen::Matrix3d covariance_of(const Joint& j);
void set_covariance(Joint& j, const Eigen::Matrix3d& c);
// The radius of the sphere round a joint's 95 % region, m (the largest axis
// of the ellipsoid x' C^-1 x <= 7.815, chi-square with 3 degrees of freedom);
// 0 without a covariance.
double radius_95(const Joint& j);
inline bool has_covariance(const Joint& j) {
  for (const float v : j.covariance)
    if (v != 0.0f) return true;
  return false;
}

struct Skeleton {
  std::string sensor_id;
  std::uint32_t person_id = 0;
  std::string frame_id;            // "world" or the sensor's frame
  std::int64_t stamp_ns = 0;       // on the source's clock
  std::uint64_t frame_number = 0;
  std::array<Joint, kJointCount> joints{};
  // Capture stamps of the inputs it was made from (fused output; a raw
  // skeleton's are its stamp_ns). 0: not given, take stamp_ns.
  std::int64_t capture_oldest_ns = 0, capture_newest_ns = 0;

  Joint& operator[](JointId id) { return joints[static_cast<std::size_t>(id)]; }
  const Joint& operator[](JointId id) const { return joints[static_cast<std::size_t>(id)]; }
};

// A sensor's pose in `frame_id` (where its frame's origin and axes are).
struct SensorPose {
  std::string sensor_id;
  std::string frame_id = "world";
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // frame_id <- sensor
  std::int64_t stamp_ns = 0;
  std::string method;  // "ground_truth", "checkerboard", "skeleton", "manual"
  double rms_residual_m = 0.0;
  double max_residual_m = 0.0;
};

// Where a skeleton is: the torso if reported, else the mean of the joints
// reported with any confidence. Empty when nothing is.
std::optional<Eigen::Vector3d> centre_of(const Skeleton& s);

// The way the chest faces as this skeleton's labels say (unit): from the
// shoulders, forward = (left - right) x up; `up` is the world's up, or the
// skeleton's own spine in a sensor's frame. Empty without both shoulders.
// A tracker takes the person to face it, so a view of the back claims the
// reverse.
std::optional<Eigen::Vector3d> claimed_facing(const Skeleton& s, const Eigen::Vector3d& up);

// The joint on the other side of the body (left hand <-> right hand); itself for the spine.
JointId mirror(JointId id);
// Swaps every left joint with its right counterpart (a tracker that sees the back labels them the other way round).
void swap_sides(Skeleton& s);

}  // namespace skelgraph::skeleton
