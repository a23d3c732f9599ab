#pragma once
// A simulated scenario scored against its truth (`skelgraph eval sim`, the
// demo's report): the simulator's tracker model, or its rendered depth images
// through the open depth tracker (one per sensor, or one fitting every
// sensor's views at once), then every single sensor and fusion method
// evaluated. No DDS.

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "skelgraph/eval/offline.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::eval {

struct SimSource {
  std::string kind = "tracker";       // tracker, depth or depth-merged
  std::string depth_size = "320x240";  // depth: the images' size (160x120, 320x240, 640x480)
  double girth = 1.1;                  // depth: the simulated people's build against the tracker's standard model
};

struct SimRun {
  OfflineResult result;
  nlohmann::json depth;  // depth: {frames, size, girth, render_ms_per_frame, track_ms_per_frame}; null otherwise
};

// Throws std::invalid_argument for a bad source or depth size. The tracker
// source is simulated and scored a minute at a time (an hour-long session is
// never held whole); `progress` says how far.
SimRun run_simulation(const sim::SimConfig& cfg, const OfflineOptions& options, const SimSource& source,
                      const std::function<void(const std::string&)>& progress = {});

// Each stream's figures (stream_json) with its fuser's counts, as `eval sim --json` gives them.
nlohmann::json streams_json(const OfflineResult& r);

}  // namespace skelgraph::eval
