#pragma once
// What the calibrations read from files. Skeletons: an MCAP recording's
// skelgraph/skeleton/raw per sensor on the recorder's clock (log time), with
// the poses its skelgraph/calibration holds (frame world); or a data set the
// playback readers know, on its own stamps. The hand at the robot's tool: the
// tool's positions (skelgraph/robot/state, world) and each sensor's tracked
// hand joints (sensor frame), per sensor and tracked person, on the
// recorder's clock (the sensors' and the robot's own stamps need not share
// one). Errors name the file: InputError.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "skelgraph/calib/robot_calib.hpp"
#include "skelgraph/calib/skeleton_calib.hpp"

namespace skelgraph::calib {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SkeletonInput {
  std::map<std::string, std::vector<TimedSkeleton>> by_sensor;
  std::map<std::string, Eigen::Isometry3d> poses;  // world_from_sensor, if recorded
  std::string skipped_note;                         // a data set's lines skipped (on_error skip), else empty
};
// `format` empty: an MCAP recording; else a playback format name (multitrack,
// generic, ...). `skip_bad_lines`: a bad line in a data-set file is skipped
// (and counted in skipped_note) instead of failing the input.
SkeletonInput read_skeleton_input(const std::string& path, const std::string& format, bool skip_bad_lines);

struct HandInput {
  std::vector<TimedPoint> tool;  // in time order
  // sensor -> (person, index into the joints asked for) -> positions, in time order
  std::map<std::string, std::map<std::pair<std::uint32_t, int>, std::vector<TimedPoint>>> hands;
  std::size_t states = 0;  // robot states read
};
// The joints asked for (a hand or both) where tracked (confidence 0.5 or
// more); throws InputError when the recording has no robot state or no such joint.
HandInput read_hand_input(const std::string& path, const std::vector<skeleton::JointId>& joints);

}  // namespace skelgraph::calib
