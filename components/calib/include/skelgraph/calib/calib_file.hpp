#pragma once
// Calibration files (YAML, under bringup/calib/ by convention): the pose of
// each sensor in one frame, how it was found and how well it fits.
//
//   # written by skelgraph calib skeleton ...
//   version: 1
//   frame_id: world
//   sensors:
//     - id: sensor1
//       translation: [0.0, 0.0, 0.0]          # m, frame_id <- sensor
//       rotation_xyzw: [0.0, 0.0, 0.0, 1.0]   # unit quaternion
//       method: skeleton                      # ground_truth | checkerboard | skeleton | manual
//       rms_residual_m: 0.0
//       max_residual_m: 0.0
//
// The `calibration` component publishes it on skelgraph/calibration, where
// fusion takes its sensor poses from.

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "skelgraph/calib/intrinsics.hpp"
#include "skelgraph/calib/robot_calib.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::calib {

class CalibFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CalibFile {
  std::string frame_id = "world";
  std::vector<skeleton::SensorPose> sensors;
  std::string comment;  // first-line comment when writing (what made it)
};

// Throws CalibFileError naming file:line and what was expected.
CalibFile read_calib_file(const std::string& path);
void write_calib_file(const std::string& path, const CalibFile& file);

// Board markers (YAML), to calibrate a sensor to a motion-capture (world)
// frame with a board as the thesis did: the markers' positions on the board
// (board frame: x along the corner rows, y down the columns, origin at the
// first inner corner; m) and, per view NAME, where the motion-capture system
// saw them (world, m, same order).
//   version: 1
//   markers_in_board: [[-0.1, -0.1, 0], ...]
//   views:
//     - name: "000"
//       markers_in_world: [[x, y, z], ...]
struct BoardMarkers {
  std::vector<Eigen::Vector3d> in_board;
  std::map<std::string, std::vector<Eigen::Vector3d>> in_world;  // by view name
};
BoardMarkers read_board_markers(const std::string& path);
void write_board_markers(const std::string& path, const BoardMarkers& m, const std::string& comment);

// Intrinsics files (YAML): version: 1, width, height, fx, fy, cx, cy,
// distortion: [k1, k2, p1, p2, k3], and how they were found
// (rms_reprojection_px, views) when written by `skelgraph calib intrinsics`.
Intrinsics read_intrinsics_file(const std::string& path);
void write_intrinsics_file(const std::string& path, const Intrinsics& k, double rms_reprojection_px, std::size_t views,
                           const std::string& comment);

// Tool poses files (YAML), for `skelgraph calib robot` with a board on the
// tool: how the board sits on the tool (its pose in the tool frame; board
// frame as above) and, per view NAME, the tool's pose in the robot's base
// frame as the robot reported it when the view was taken.
//   version: 1
//   robot: UR5e
//   board_on_tool: {translation: [0, 0, 0.01], rotation_xyzw: [1, 0, 0, 0]}
//   views:
//     - {name: "000", translation: [x, y, z], rotation_xyzw: [x, y, z, w]}
ToolPoses read_tool_poses(const std::string& path);
void write_tool_poses(const std::string& path, const ToolPoses& t, const std::string& comment);

// A rigid transform from a file (`bag import-bvh --transform`): either
//   rotation: [9 numbers, row-major]
//   translation: [x, y, z]   # metres
// or a calibration file, whose sensor `sensor_id` is the pose wanted (the
// motion-capture system's in the file's frame). Throws CalibFileError naming
// the file and what was wrong (not YAML, no such sensor, not a rotation).
Eigen::Isometry3d read_transform_file(const std::string& path, const std::string& sensor_id);

}  // namespace skelgraph::calib
