#pragma once
// Pointing to fetch, measured on simulated sessions (no DDS): a classifier
// trained on simulated pointing sessions spots pointing in others it never
// saw (gesture/sim_sessions.hpp); for every true pointing whose spot the
// robot can reach, the spotted target (if any) sends the simulated arm's tool
// to hover above it (robot/fetch.hpp), and where the tool ends is compared
// with the true spot, horizontally. The separation monitor is not in this
// loop (the worker stands 1-3 m from the spot): it is measured apart
// (eval/safety.hpp).

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/robot/fetch.hpp"

namespace skelgraph::eval {

struct FetchRunOptions {
  int train_sessions = gesture::kTrainSessions;
  int sessions = 8;  // held out
  std::uint64_t seed = 1;
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();
  robot::FetchParams fetch;
  double tool_speed = 0.5;  // m/s
  double settle_s = 4.0;    // the arm moves this long towards the target
  double within_m = 0.15;   // success: the tool this close to the true spot, horizontally
};

struct FetchRunResult {
  int pointing = 0;   // true pointing gestures with a floor spot
  int in_reach = 0;   // ... whose spot the robot can reach
  int spotted = 0;    // ... of those, spotted with a target
  int fetched = 0;    // ... whose spotted target was in reach too (the tool went)
  int within = 0;     // ... and ended within within_m of the true spot
  std::vector<double> error_m;  // per fetch: the tool from the true spot, horizontally
};

FetchRunResult run_fetch(const FetchRunOptions& options);

}  // namespace skelgraph::eval
