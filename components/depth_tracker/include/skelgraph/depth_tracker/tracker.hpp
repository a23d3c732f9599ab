#pragma once
// Open skeleton tracking from depth (no DDS): people found in a depth image
// as person-shaped regions above the floor, and the 15-joint body model
// fitted to each person's points frame by frame, starting from the previous
// pose.
//
// The model is a set of capsules (head, neck, trunk, arms, hands, legs) hung
// on the joints; the fit moves the 15 joints (45 unknowns) to minimise, by
// Gauss-Newton, the distance of each point to the surface of its nearest
// capsule (robust: far points are ignored, mid ones down-weighted), plus the
// deviation of bone lengths (and the trunk's shape) from the person's, plus
// a pull towards the previous pose, plus penalties for joint limits broken
// (JointLimits: elbows and knees not folded too tight, knees not bent
// backwards). A new person starts from a standing
// template facing the sensor, scaled to the height of their region; a person
// not seen for `lost_after_s` is dropped and starts again when found.
// Per-joint confidence: 1 when enough points support the joint's segments,
// 0.5 (inferred) when not, 0 when it lies outside the image (a close,
// upper-body view: the legs below its lower edge); the sided joints (shoulders, arms, legs) are
// reported at confidence 0 whenever the person is seen side-on, where front
// and back (and so left and right) cannot be told apart: fusion then takes
// them from a sensor that can tell.
//
// Frames: the image's sensor frame (skeletons are reported in it, like any
// tracker's), and a world frame with y up and the floor at y = 0, given by the
// sensor's pose (set_pose; default: a level sensor 1.2 m above the floor).

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "skelgraph/depth/cloud.hpp"
#include "skelgraph/depth/depth_image.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::depth_tracker {

// What a body can do, as the fit enforces it: elbows and knees bend no
// tighter than these angles (between the two bones meeting there: 180 is
// straight), and knees bend forwards only (the knee no more than
// `knee_back_m` behind the hip-foot line, "forwards" being the way the
// hips and trunk face).
struct JointLimits {
  double min_elbow_deg = 30.0;
  double min_knee_deg = 40.0;
  double knee_back_m = 0.02;
};
struct TrackerOptions {
  double voxel_m = 0.03;           // the person's points are thinned to one per cube of this side
  int iterations = 6;              // Gauss-Newton steps per frame
  int init_iterations = 30;        // ... for a new person
  double floor_margin_m = 0.05;    // points this close above the floor are floor
  double max_step_m = 0.08;        // neighbouring pixels further apart in depth belong to different regions
  double min_height_m = 0.9, max_height_m = 2.4;  // a person's region: top above the floor
  double min_extent_m = 0.8;       // ... and vertical extent (legs may be out of view)
  double min_upper_extent_m = 0.4; // ... for a region cut off by the image's lower edge (a close, upper-body view)
  double min_thickness_m = 0.015;  // ... and not flat: spread across its flattest direction (sd)
  double max_distance_m = 5.0;     // ... and this close to the sensor (Kinect-class trackers reach ~4 m)
  double max_width_m = 2.2;        // ... and horizontal extent (arms spread: about the height)
  std::size_t min_points = 60;     // ... and points after thinning
  double max_hand_part_m = 0.4;    // a region no bigger than this across (a hand or forearm held out) ...
  double hand_reach_m = 0.45;      // ... nearer the sensor than a person and this close to them is theirs
  double outlier_m = 0.15;         // points farther than this from the model's surface are ignored
  double bone_weight = 30.0;       // per bone, against one point
  double smooth_weight = 0.5;      // per joint, pull towards the previous frame's pose
  double match_radius_m = 0.7;     // a region continues a person whose pelvis was this close
  double lost_after_s = 0.5;
  double tracked_support = 8;      // points on a joint's segments for confidence 1
  JointLimits limits;
  double limit_weight = 200.0;     // per broken limit, against one point; 0 turns the limits off
  double free_space_m = 0.03;      // a joint may lie this far in front of the surface seen at its pixel ...
  double free_space_weight = 100.0;  // ... beyond it, this penalty (against one point; 0: off) ...
  double free_space_depth_m = 0.3;   // ... up to this far in front (farther: the joint is beside a thin limb, the pixel the room behind)
};

// How far a skeleton breaks the limits: the worst amount per limit (0 when
// kept). Frame-free (uses the body's own up and forward).
struct LimitViolation {
  double elbow_deg = 0.0, knee_deg = 0.0, knee_back_m = 0.0;
  bool any() const { return elbow_deg > 0 || knee_deg > 0 || knee_back_m > 0; }
};
LimitViolation check_joint_limits(const skeleton::Skeleton& s, const JointLimits& limits = {});

struct TrackerStats {
  std::uint64_t frames = 0, regions = 0, people_reported = 0, initialisations = 0;
  double mean_points = 0.0;       // per reported person
  double mean_residual_m = 0.0;   // mean |distance to surface| of inlying points, last frame
};

// A person-shaped group of points (world frame, thinned), as the tracker finds them.
struct PersonPoints {
  depth::Points points;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double top = 0.0;  // height of its top above the floor, m
  bool cut_at_bottom = false;  // reaches the image's lower edge: the legs are out of view
  double crown = 0.0;  // the height of its top over its middle (the head's; hands raised beside it aside), m
};
// The people in a depth image (step 1 above), without fitting anyone: for
// point clouds of people and for tests. Throws std::invalid_argument for a malformed image.
std::vector<PersonPoints> find_people(const depth::DepthImage& image, const Eigen::Isometry3d& world_from_sensor,
                                      const TrackerOptions& options = {});

// Whether a joint (sensor frame) lies on what the image shows: its pixel has
// a reading and the joint is no more than `margin_m` in front of that
// surface (behind it is fine: joints are inside the body). For checking a
// tracker on real depth without ground truth (`skelgraph depth track`).
bool on_surface(const depth::DepthImage& image, const Eigen::Vector3d& joint, double margin_m = 0.05);

class DepthTracker {
 public:
  explicit DepthTracker(TrackerOptions options = {});
  ~DepthTracker();
  DepthTracker(DepthTracker&&) noexcept;
  DepthTracker& operator=(DepthTracker&&) noexcept;

  // The sensor's pose in a world frame with y up and the floor at y = 0.
  void set_pose(const Eigen::Isometry3d& world_from_sensor);
  const Eigen::Isometry3d& pose() const;

  // The people in the image: skeletons in the sensor frame, stamped and
  // numbered like the image, person ids stable while a person is tracked.
  // Throws std::invalid_argument for a malformed image.
  std::vector<skeleton::Skeleton> track(const depth::DepthImage& image);
  // Several calibrated sensors' images of about the same moment, fitted as
  // one: each person's points from every sensor merged in the world frame.
  // Skeletons in the world frame, sensor_id `id`. Use a tracker either for
  // one sensor (track) or for merged views (track_merged), not both.
  std::vector<skeleton::Skeleton> track_merged(const std::vector<depth::DepthImage>& images,
                                               const std::vector<Eigen::Isometry3d>& world_from_sensor,
                                               const std::string& id = "merged");

  // Ids of the people forgotten (not seen for lost_after_s) since the last call.
  std::vector<std::uint32_t> take_dropped();

  const TrackerStats& stats() const;
  const TrackerOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skelgraph::depth_tracker
