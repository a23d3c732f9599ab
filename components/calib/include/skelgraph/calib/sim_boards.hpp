#pragma once
// Synthetic calibration inputs from a simulated cell (`skelgraph sim boards`):
// checkerboard views (colour and depth PNGs) every sensor sees, views for
// each sensor's intrinsics, the true poses and intrinsics, and the board's
// motion-capture markers; or, with a robot, the board on the tool of a
// simulated UR5e moved through poses facing each sensor, with the tool poses
// the robot reports (an absolute error of millimetres). Files only, no DDS.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/calib/board.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::calib {

// The simulated sensors' true poses, as a calibration file says them.
CalibFile true_poses(const sim::SimConfig& cfg, const std::string& comment);

struct SimBoardsOptions {
  std::string dir;             // written into (created)
  Board board;                 // the checkerboard
  double grey_noise = 2.0;     // image noise, grey levels
  double depth_noise = 1.0;    // scale of Kinect-like depth noise
  int views = 20;              // views every sensor sees (robot: poses facing each sensor)
  int intrinsics_views = 15;   // views per sensor for its intrinsics (not with a robot)
  std::uint64_t seed = 1;
};

struct SimBoardsSummary {
  std::size_t views = 0, images = 0;
  std::vector<std::pair<std::string, std::size_t>> intrinsics_views;  // per sensor
};

// DIR/<sensor>/NNN_color.png + NNN_depth.png (the board where every sensor
// sees it, the same NNN at the same moment), DIR/<sensor>/intrinsics/ (views
// for that sensor's intrinsics), DIR/truth.yaml (poses),
// DIR/<sensor>/intrinsics_truth.yaml and DIR/markers.yaml (the board's
// markers in each shared view, 0.5 mm of noise). Throws CalibError when no
// board pose is seen by every sensor (too far apart), CalibFileError when a
// file cannot be written.
SimBoardsSummary write_sim_boards(const sim::SimConfig& cfg, const SimBoardsOptions& o);

struct RobotBoardsOptions {
  SimBoardsOptions boards;
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();
  std::string base_text;          // as given (file comments, messages)
  double tool_noise_mm = 1.0;     // error of the reported tool positions, per axis (sd)
  double tool_noise_deg = 0.1;    // ... and orientations
};

struct RobotBoardsSummary {
  std::size_t robot_poses = 0, images = 0;
  std::map<std::string, std::size_t> views;  // per sensor
};

// The board on the tool of a simulated UR5e standing at world_from_base,
// moved through `views` poses facing each sensor (any other sensor that sees
// a pose gets its view too), drawn at random joint angles with the whole arm
// above the floor: DIR/<sensor>/NNN_color.png + NNN_depth.png +
// intrinsics.yaml (the true intrinsics), DIR/tool_poses.yaml (what the robot
// reports, and the mount), DIR/truth.yaml. The arm itself is not drawn.
// Throws CalibError when a sensor sees the board in fewer than `views` poses.
RobotBoardsSummary write_sim_robot_boards(const sim::SimConfig& cfg, const RobotBoardsOptions& o);

}  // namespace skelgraph::calib
