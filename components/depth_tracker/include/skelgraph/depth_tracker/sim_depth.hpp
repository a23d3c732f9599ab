#pragma once
// The depth path offline: a simulated cell's depth images (sim/depth_render.hpp)
// through one DepthTracker per sensor, as time-ordered raw skeletons beside
// the ground truth, ready for eval::evaluate. Used by `skelgraph eval sim
// --source depth` and bench/depth_tracker.

#include <vector>

#include "skelgraph/depth_tracker/tracker.hpp"
#include "skelgraph/eval/offline.hpp"
#include "skelgraph/sim/depth_render.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::depth_tracker {

struct SimDepthOptions {
  calib::Intrinsics intrinsics = depth::kinect_intrinsics(320, 240);
  sim::DepthNoise noise;
  TrackerOptions tracker;
  double girth = 1.0;  // the simulated people's build (1: the renderer's standard capsules)
  // One tracker fitting every sensor's points at once (track_merged), run on
  // each frame of the first sensor with the others' latest images: raw
  // skeletons with sensor_id "merged" in the world frame (pose: identity).
  bool merged = false;
};

struct SimDepthResult {
  std::vector<eval::TimedSkeleton> events;  // truth (world) and tracked raw skeletons (sensor frames), in time order
  std::uint64_t frames = 0;                 // depth images rendered and tracked
  double render_s = 0.0, track_s = 0.0;     // time spent, s
};

// Runs the whole scenario. The trackers know each sensor's true pose (as a
// calibration would give them).
SimDepthResult track_simulated_depth(sim::SimConfig config, const SimDepthOptions& options);

}  // namespace skelgraph::depth_tracker
