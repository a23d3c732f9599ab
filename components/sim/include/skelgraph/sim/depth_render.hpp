#pragma once
// What a Kinect-like depth sensor of the virtual work cell sees: the people as
// capsules around their true skeletons, the scenario's props, the floor and
// the room's walls, ray-cast per pixel, then Kinect v1 depth errors
// (disparity noise and 1/8-pixel disparity quantisation, so errors grow with
// the square of depth; no reading out of range, random drop-outs, and missing
// pixels along depth edges where the projector's pattern is shadowed).
// Deterministic for a given Rng. DDS-free.

#include <vector>

#include "skelgraph/depth/depth_image.hpp"
#include "skelgraph/sim/rng.hpp"
#include "skelgraph/sim/scenario.hpp"
#include "skelgraph/sim/sensor.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::sim {

struct DepthNoise {
  bool enabled = true;
  double focal_px = 580.0;          // the IR camera's focal length at 640x480 (disparity is measured there)
  double baseline_m = 0.075;        // projector to camera
  double disparity_sd_px = 0.05;    // random disparity error
  double disparity_step_px = 0.125; // quantisation (the Kinect reports 1/8 pixel)
  double edge_jump_m = 0.05;        // a neighbour this much nearer makes a depth edge ...
  double edge_drop = 0.5;           // ... where the pixel has no reading with this chance
  double random_drop = 0.002;       // chance any pixel has no reading
  double min_range_m = 0.5, max_range_m = 8.0;
};

// The body's volume around a (true, world-frame) skeleton, scaled by body
// height: head, neck, trunk, arms, hands, legs as capsules. `girth` scales
// every radius but the head's (builds differ: 0.85 slim .. 1.25 stout).
std::vector<Capsule> body_capsules(const skeleton::Skeleton& skeleton, double height_m = 1.75, double girth = 1.0);

struct Room {
  bool enabled = true;
  Eigen::AlignedBox3d box{Eigen::Vector3d(-4.0, 0.0, -4.0), Eigen::Vector3d(4.0, 3.0, 4.0)};  // walls, floor, ceiling
};

class DepthRenderer {
 public:
  // Throws std::invalid_argument for bad intrinsics or noise settings.
  DepthRenderer(const SensorConfig& sensor, const calib::Intrinsics& intrinsics, DepthNoise noise = {}, Room room = {});

  // The depth image of the scene: people (world-frame truth skeletons), props
  // and room. sensor_id is set; stamp and frame number are the caller's.
  depth::DepthImage render(const std::vector<skeleton::Skeleton>& people, const std::vector<Obstacle>& obstacles,
                           Rng& rng, double height_m = 1.75, double girth = 1.0) const;
  // The same without noise, drop-outs or range limits other than the room: exact depth in metres (0: nothing).
  std::vector<float> render_exact(const std::vector<skeleton::Skeleton>& people, const std::vector<Obstacle>& obstacles,
                                  double height_m = 1.75, double girth = 1.0) const;

  const calib::Intrinsics& intrinsics() const { return k_; }
  const SensorView& view() const { return view_; }

 private:
  SensorView view_;
  calib::Intrinsics k_;
  DepthNoise noise_;
  Room room_;
  std::vector<Eigen::Vector3d> rays_;  // per pixel, sensor frame, z = 1
};

}  // namespace skelgraph::sim
