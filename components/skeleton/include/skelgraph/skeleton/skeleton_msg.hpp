#pragma once
// Conversion between the canonical skeleton and the wire type (adapters only).

#include "skelgraph/msg/messages.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::skeleton {

msg::Skeleton to_msg(const Skeleton& s);
Skeleton from_msg(const msg::Skeleton& m);

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
msg::SensorPose to_msg(const SensorPose& p);
SensorPose from_msg(const msg::SensorPose& m);

}  // namespace skelgraph::skeleton
