#pragma once
// Sensors into a robot's frame, from pairs of (a point whose place the robot
// reports, the same point seen by a sensor). Two ways:
//   - a checkerboard mounted on the tool: per pose, its corners in the base
//     frame (the reported tool pose times the mount) against the corners
//     found in the sensor's colour image and lifted with its depth;
//   - a person's hand held at the tool: at moments when both hold still, the
//     tool point (base frame) against the hand joint of the sensor's skeleton.
// Both end in one RANSAC + SVD fit per sensor. Eigen only, no I/O; the tool
// poses file is read in calib_file.hpp.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/calib/rigid.hpp"

namespace skelgraph::calib {

// What the robot reported for each pose of a board calibration, and how the
// board sits on the tool.
struct ToolPoses {
  std::string robot;                                              // e.g. "UR5e", for the record
  Eigen::Isometry3d tool_from_board = Eigen::Isometry3d::Identity();
  std::map<std::string, Eigen::Isometry3d> base_from_tool;        // by view name
};

struct RobotFit {
  // The sensor in the robot's base frame (skelgraph sensor frame: x left,
  // y up, z forward).
  Eigen::Isometry3d base_from_sensor = Eigen::Isometry3d::Identity();
  RansacResult ransac;           // the fit of sensor points onto base points
  std::size_t points = 0;        // pairs offered
  std::size_t views = 0;         // board poses, or hand holds
};

// Board on the tool: `corners_camera[v]` the corners of view v in the
// sensor's camera frame (OpenCV: x right, y down; lift_corners), and
// `base_from_board[v]` the board's pose in the base for that view, board
// object points `object_points` (Board::object_points()). RANSAC at 2 cm.
// Throws CalibError with fewer than 3 views or inconsistent sizes.
RobotFit fit_board_on_tool(const std::vector<std::vector<Eigen::Vector3d>>& corners_camera,
                           const std::vector<Eigen::Isometry3d>& base_from_board,
                           const std::vector<Eigen::Vector3d>& object_points);

// A point over time (a tool point in the base frame, a hand joint in a
// sensor's frame).
struct TimedPoint {
  std::int64_t t_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

struct HoldOptions {
  double hold_s = 1.0;          // both still this long
  double tool_still_m = 0.005;  // the tool moves less than this over the hold
  double hand_still_m = 0.2;    // the hand joint less than this: a tracker's hand jitters by 3-10 cm
  double min_gap_m = 0.05;      // holds closer than this to the previous one (tool) are the same pose
  std::int64_t max_skew_ns = 100'000'000;  // a hand sample counts for a tool time within this
  std::int64_t max_gap_ns = 200'000'000;   // samples further apart break a stretch (the hand was lost)
};

struct Hold {
  std::int64_t start_ns = 0, end_ns = 0;
  Eigen::Vector3d tool = Eigen::Vector3d::Zero();  // median over the hold
  Eigen::Vector3d hand = Eigen::Vector3d::Zero();
  std::size_t hand_samples = 0;
};

// The moments when the tool and the hand both hold still for hold_s, one per
// tool pose (the longest still stretch), with the medians of both. Both
// series sorted by time.
std::vector<Hold> find_holds(const std::vector<TimedPoint>& tool, const std::vector<TimedPoint>& hand,
                             const HoldOptions& options = {});

// Hand at the tool: the holds' hand points (sensor frame) onto their tool
// points (base frame), RANSAC at `inlier_m` (a hand is not a marker: the
// joint sits a few cm from where it touches). Throws CalibError with fewer
// than 4 holds or holds on a line.
RobotFit fit_hand_at_tool(const std::vector<Hold>& holds, double inlier_m = 0.08);

// How many places the tool held still at, over the holds `which` (holds
// closer than min_gap_m are one place; both hands may pair with one).
std::size_t count_places(const std::vector<Hold>& holds, const std::vector<std::size_t>& which, double min_gap_m);

// One sensor's pose from a hand at the tool, and how well it is backed.
struct HandFit {
  std::string sensor;
  RobotFit fit;
  std::size_t holds = 0;            // holds offered
  std::size_t places = 0;           // places the tool held still at
  std::size_t places_agreeing = 0;  // of them, where a hand agreed (RANSAC inliers)
};

struct HandCalibration {
  std::vector<HandFit> fits;
  std::vector<std::string> failed;  // "sensor: why", for sensors without a fit
};

struct HandCalibOptions {
  HoldOptions holds;
  double inlier_m = 0.08;
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();  // where the robot's base stands
  // The sensors already calibrated to each other (world_from_sensor): every
  // sensor's holds are pooled in that frame and fitted once for the whole
  // cell (the sensors' hand errors differ by view and partly cancel), each
  // sensor then placed through its pose in the cell. Empty: one fit per sensor.
  std::map<std::string, Eigen::Isometry3d> cell;
  std::string cell_name = "the cell";  // where the cell came from, for messages
};

// The hand at the tool end to end: `tool` the tool point in the robot's world
// (time order), `hands` per sensor and (person, joint) the hand joint in the
// sensor's frame (read_hand_input). Each person's holds (find_holds) go to the
// robot's base, then to one fit per sensor or for the cell. A sensor that
// cannot be fitted is named in `failed` with the reason.
HandCalibration calibrate_hand_at_tool(
    const std::vector<TimedPoint>& tool,
    const std::map<std::string, std::map<std::pair<std::uint32_t, int>, std::vector<TimedPoint>>>& hands,
    const HandCalibOptions& options = {});

// Verdicts. A board's corners agree within 1 cm RMS with at most 20 %
// outliers; a hand (a joint a few cm from the touch, and a tracker's noise)
// within 4 cm RMS at 80 % of the places or more.
bool board_fit_good(const RobotFit& fit);
bool hand_fit_good(const HandFit& fit);

}  // namespace skelgraph::calib
