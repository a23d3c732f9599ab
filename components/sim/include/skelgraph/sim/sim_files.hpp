#pragma once
// A simulation written to files, for tools that read recordings rather than
// the live graph: `skelgraph sim export` (generic CSV of the truth and each
// sensor, the people's phases, the truth as motion capture) and `sim
// hand-at-tool` (a recording of a person's hand held at a robot's tool, for
// `calib robot --hand`). No DDS: the recording is written with the MCAP
// library.

#include <cstddef>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::sim {

// Called every 5 s of simulated time: (simulated so far, the whole run), s.
using SimProgress = std::function<void(double done_s, double total_s)>;

struct ExportSummary {
  double duration_s = 0;
  nlohmann::json files;  // file name -> rows (or why it was not written)
};

// DIR/truth.csv, DIR/raw_<sensor>.csv (generic CSV with the run's metadata),
// DIR/phases.csv (stamp_ns,person_id,phase) and DIR/truth.bvh when one person
// is there from start to end at a steady rate. Throws std::runtime_error when
// a file cannot be written.
ExportSummary export_simulation(const SimConfig& cfg, const std::string& dir, const SimProgress& progress = {});

struct HandAtToolOptions {
  double contact_cm = 3.0;     // the tool point beyond the hand joint, along the forearm
  double tool_noise_mm = 1.0;  // the reported positions' error, per axis (sd), smooth over the workspace
};

struct HandAtToolSummary {
  double duration_s = 0;
  std::size_t robot_states = 0, raw_skeletons = 0;
};

// A simulation whose first person's right hand a robot's tool touches
// wherever the hand is (the tool point `contact_cm` beyond the hand joint
// along the forearm, where the palm closes round it); the robot's reported
// position has an error of `tool_noise_mm` that varies smoothly over the
// workspace (a robot's absolute accuracy). Written to `out` as a recording:
// the sensors' skeletons (skeleton/raw), the truth, the true sensor poses
// (calibration) and the tool (robot/state, world, at the truth's rate).
HandAtToolSummary write_hand_at_tool(const SimConfig& cfg, const std::string& out, const HandAtToolOptions& o,
                                     const SimProgress& progress = {});

}  // namespace skelgraph::sim
