#pragma once
// `skelgraph calib`: what its subcommands (cmd_calib*.cpp) share: their
// options, entry points, and the conversions of the libraries' errors about
// files the user named into usage errors.

#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/calib/board.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/calib/skeleton_run.hpp"

namespace skelgraph::cli::calib_cmd {

struct SkelOptions {
  std::vector<std::string> inputs;
  std::string format;  // empty: MCAP recordings
  std::string ref, other, out, ref_pose, prior;
  std::string on_error = "stop";  // a bad line in a data-set file: stop (the input is bad) or skip it
  double threshold_m = 0.12, clock_search_ms = 0, robust_scale_m = 0.05;
  bool holdout = false, json = false, best_rigid = false;
  int best_rigid_starts = 1;
};

struct SimCalibOptions {
  std::vector<std::string> layouts{"ring:3", "ring:4", "ring:6", "corners:4"};
  std::vector<std::string> scenarios{"walk", "360"};
  std::vector<int> seeds{1, 2, 3};
  double seconds = 60;
  std::vector<std::string> params;
  double target_deg = 1.0, target_cm = 2.0;
  bool json = false, floor = false;
};

struct BoardOptions {
  std::vector<std::string> images;  // intrinsics
  std::string ref_dir, other_dir, ref = "sensor1", other = "sensor2";
  std::string size = "9x6";
  double square_m = 0.08;
  std::string ref_intrinsics, other_intrinsics, ref_pose, out;
  std::string world_markers;  // one directory: its sensor to the motion-capture frame
  bool json = false;
};

struct RobotOptions {
  std::vector<std::string> dirs;  // board on the tool: one directory of views per sensor
  std::string tool_poses;         // ... and what the robot reported for each view
  std::string hand_recording;     // hand at the tool: a recording of robot/state and skeleton/raw
  std::string hand = "either";
  std::string intrinsics;         // for every directory (default DIR/intrinsics.yaml)
  std::string base = "0,0,1.5,180";
  std::string size = "9x6";
  double square_m = 0.08, hold_s = 1.0, inlier_cm = 8.0;
  std::string truth, out, cell;
  bool json = false;
};

int calib_skeleton(const SkelOptions& o);
int calib_sim(const SimCalibOptions& o);
int calib_intrinsics(const BoardOptions& o);
int calib_board(const BoardOptions& o);
int calib_robot(const RobotOptions& o);

using calib::cm;         // metres to centimetres, rounded to mm
using calib::pose_json;  // translation_m, rotation_xyzw, rotation_deg
// The reference sensor's pose in the world: from a calibration file, or the
// identity (the reference's frame is the world) without one.
Eigen::Isometry3d reference_in_world(const std::string& file, const std::string& ref);
// A calibration file's poses (world_from_sensor): --prior, --truth, --cell.
std::map<std::string, Eigen::Isometry3d> prior_poses(const std::string& file);
void write_calib(const std::string& out, const calib::CalibFile& f);
// A directory's intrinsics (DIR/intrinsics.yaml unless given).
calib::Intrinsics intrinsics_for(const std::string& dir, const std::string& given);
// The library's board views (calib/board.hpp).
std::vector<std::string> view_names(const std::string& dir);
std::optional<std::vector<Eigen::Vector3d>> lift_view(const std::string& dir, const std::string& name,
                                                      const calib::Board& board, const calib::Intrinsics& k,
                                                      std::string* why);

}  // namespace skelgraph::cli::calib_cmd
