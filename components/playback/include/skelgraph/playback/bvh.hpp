#pragma once
// Motion capture as ground truth: BVH files (a joint hierarchy with offsets
// and channels, then one line of channel values per frame), forward
// kinematics to joint positions, and a mapping of the mocap skeleton's joints
// onto the canonical 15. Mocap skeletons name joints differently: the
// default mapping knows the common names (CMU, Mixamo, Vicon/Motive-style),
// a YAML file overrides it. Positions are moved into a sensor's or the
// world's frame by a rigid transform and scaled from the file's units to
// metres; time starts at `time_offset_s`. No DDS.
//
// BVH conventions: a joint's local transform is a translation (its OFFSET
// plus any position channels) then its rotation channels applied in the
// order listed (intrinsic: R = R_first * R_second * R_third), in degrees;
// global = parent's global * local; a joint's position is its global
// translation.
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/playback/readers.hpp"

namespace skelgraph::playback {

struct BvhJoint {
  std::string name;
  int parent = -1;                    // index, -1 for the root
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  std::vector<std::string> channels;  // Xposition ... Zrotation, in file order
  std::size_t first_channel = 0;      // its first value's column in a frame line
  bool end_site = false;              // an "End Site": no channels, kept for completeness
};

struct Bvh {
  std::vector<BvhJoint> joints;       // parents before children
  double frame_time_s = 0.0;
  std::vector<std::vector<double>> frames;  // channel values per frame
  std::size_t channel_count = 0;
  int index_of(const std::string& name) const;  // -1 when absent
  // Every joint's global position in frame `f` (file units, the file's frame).
  std::vector<Eigen::Vector3d> positions(std::size_t f) const;
};

// Throws DataError naming file:line (a bad keyword, a missing brace, a
// channel count that does not match, a frame line of the wrong length, a
// non-finite number, a frame count that does not match).
Bvh read_bvh(const std::string& path);

struct BvhOptions {
  double units_to_m = 0.01;  // the file's units in metres (cm: 0.01; mm: 0.001; m: 1)
  Eigen::Isometry3d target_from_mocap = Eigen::Isometry3d::Identity();  // into the sensor's or the world's frame
  std::string frame_id = "world";    // the frame the positions end up in
  std::string sensor_id = "mocap";
  double time_offset_s = 0.0;        // frame 0's time (the recording's clock)
  // Matched moments (mocap frame, its time on the recording's clock, s): when
  // given, frame f's time is the least-squares line through them (one point:
  // that time and the file's frame time), so a mocap clock running at another
  // rate is followed; time_offset_s is then not used.
  std::vector<std::pair<std::size_t, double>> time_points;
  std::map<std::string, std::string> joints;  // canonical name -> BVH joint; empty: the default mapping
};

// The default mapping's candidates per canonical joint (the first one the file has wins).
const std::map<std::string, std::vector<std::string>>& default_bvh_mapping();
// Matched moments, CSV with the header `mocap_frame,time_s`; throws DataError naming file:line.
std::vector<std::pair<std::size_t, double>> read_bvh_time_points(const std::string& path);

// A mapping YAML file: `joints: {head: Head, left_hand: LeftHand, ...}`
// (canonical names as in skeleton.hpp); throws DataError naming the file.
std::map<std::string, std::string> read_bvh_mapping(const std::string& path);

// The BVH as a recording of skeletons (confidence 1; a canonical joint the
// mapping cannot find is an error naming it and the file's joints).
Recording bvh_recording(const std::string& path, const Bvh& bvh, const BvhOptions& options);

// A BVH of these skeletons with position channels only (every canonical
// joint a child of the torso or of its limb's previous joint, no rotations):
// what read_bvh and bvh_recording give back exactly (the round trip test).
void write_position_bvh(const std::vector<skeleton::Skeleton>& frames, double frame_time_s, double units_per_m,
                        std::ostream& out);

}  // namespace skelgraph::playback
