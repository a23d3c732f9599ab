#pragma once
// How realistic the simulator is: one sensor, one person, each thesis
// scenario, each tracker profile, measured the way the thesis measured its
// Kinects against Vicon (section 5.1): the detection rate of a joint group is
// the share of sensor frames in which its joints report confidence 1; its
// error is the mean distance to ground truth over those joints only.
// `skelgraph sim table` prints the comparison (compare_with_thesis);
// tests/unit/test_sim_realism.cpp holds it to loose tolerances.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "skelgraph/eval/metrics.hpp"

namespace skelgraph::sim {

using eval::group_names;  // Head, Neck, Torso, Shoulders, Elbows, Hands
using eval::kGroupCount;
inline const std::vector<std::string> kThesisScenarios{"walk", "360", "hide", "box", "occ", "sit", "arms"};

using eval::Figures;  // per group: detection_pct (confidence 1), error_cm (mean over those)
using eval::GroupFigures;

// Tables 5.1 and 5.2 of the thesis. Throws std::invalid_argument for a scenario or profile it does not have.
Figures thesis_figures(const std::string& scenario, const std::string& profile);

struct RealismOptions {
  std::uint64_t seed = 1;
  int repeats = 2;
  double noise_scale = 1.0;
};
// Runs the simulator with its first default sensor only and measures it.
Figures simulate_figures(const std::string& scenario, const std::string& profile, const RealismOptions& opt);

// Loose agreement: detection within 20 points, error within a factor of two
// or 6 cm of the thesis.
bool detection_close(double sim, double thesis);
bool error_close(double sim, double thesis);

// One joint group of one scenario and tracker profile, simulated and in the thesis.
struct ThesisCell {
  std::string profile, scenario;
  std::size_t group = 0;
  GroupFigures sim, thesis;
  bool detection_close = false, error_close = false;  // an error the simulator cannot give (NaN) is not close
};
// The whole comparison, in the order the table prints it: by tracker profile,
// then joint group, then scenario. `on_scenario(profile, scenario)` is called
// before each simulation (progress).
std::vector<ThesisCell> compare_with_thesis(
    const RealismOptions& opt,
    const std::function<void(const std::string& profile, const std::string& scenario)>& on_scenario = {});

}  // namespace skelgraph::sim
