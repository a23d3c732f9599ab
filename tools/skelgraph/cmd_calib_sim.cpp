// skelgraph calib sim: the whole simulated cell calibrated from its
// skeletons and checked against its truth (calib/sim_check.hpp), over
// layouts, scenarios and seeds.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "cmd_calib.hpp"
#include "skelgraph/calib/board.hpp"
#include "skelgraph/skeleton/json_number.hpp"
#include "skelgraph/skeleton/stats.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/calib/calibration_step.hpp"
#include "skelgraph/calib/inputs.hpp"
#include "skelgraph/calib/sim_check.hpp"
#include "skelgraph/calib/skeleton_calib.hpp"
#include "skelgraph/eval/metrics.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::cli::calib_cmd {

namespace {


nlohmann::json calib_sim_run(const SimCalibOptions& o, const std::string& layout, const std::string& scenario, int seed) {
  const auto colon = layout.find(':');
  if (colon == std::string::npos) throw UsageError("--layouts: '" + layout + "' is not LAYOUT:SENSORS, e.g. ring:3");
  const std::string name = layout.substr(0, colon), count = layout.substr(colon + 1);
  const sim::SimConfig cfg = sim_config(o.params, "calib sim",
                                        {{"layout", name, "--layouts"},
                                         {"sensor_count", count, "--layouts"},
                                         {"scenario", scenario, "--scenarios"},
                                         {"seed", std::to_string(seed), "--seeds"},
                                         {"repeats", "1000", "calib sim"}});
  const auto check = calib::check_cell_calibration(cfg, o.seconds, o.floor);
  nlohmann::json run{{"layout", name}, {"sensor_count", cfg.sensors.size()}, {"scenario", scenario}, {"seed", seed},
                     {"seconds", o.seconds}, {"reference", check.reference}};
  if (!check.error.empty()) {
    run["error"] = check.error;
    run["within_target"] = false;
    return run;
  }
  auto& sensors = run["sensors"] = nlohmann::json::array();
  for (const auto& s : check.sensors) {
    nlohmann::json j{{"sensor", s.sensor}, {"frames", s.frames}, {"placed", s.placed}};
    if (s.placed) {
      j["path"] = s.fit.path;
      j["ambiguous"] = s.fit.ambiguous;
      j["rotation_error_deg"] = s.error.deg;
      j["translation_error_cm"] = s.error.cm;
      j["median_distance_cm"] = json_number(cm(s.fit.median_m));
      if (s.pair && s.pair->solved) {
        const auto& f = s.pair->fit;
        j["pair_alone"] = {{"rotation_error_deg", s.pair_error.deg}, {"translation_error_cm", s.pair_error.cm},
                           {"mirrored_frames", f.mirrored}, {"matched_frames", f.matched}, {"ambiguous", f.ambiguous},
                           {"inliers", f.inliers}, {"turned_inliers", f.turned_inliers}};
      } else if (s.pair) {
        j["pair_alone"] = {{"error", s.pair->error}};
      }
      if (s.floor) {
        // The floor: how far the pose the skeletons themselves favour is from the truth, which no calibration from them can undo.
        j["floor"] = {{"rotation_error_deg", s.floor_error.deg}, {"translation_error_cm", s.floor_error.cm},
                      {"median_cm", json_number(cm(s.floor->median_m))},
                      {"median_at_truth_cm", json_number(cm(s.floor->start_median_m))}};
      }
    }
    sensors.push_back(j);
  }
  run["max_rotation_error_deg"] = check.worst.deg;
  run["max_translation_error_cm"] = check.worst.cm;
  run["within_target"] = check.within(o.target_deg, o.target_cm);
  return run;
}

}  // namespace

int calib_sim(const SimCalibOptions& o) {
  nlohmann::json runs = nlohmann::json::array();
  const std::size_t total = o.layouts.size() * o.scenarios.size() * o.seeds.size();
  Progress progress;  // on stderr, with --json too: a run takes seconds
  std::size_t within = 0;
  double worst_deg = 0, worst_cm = 0;
  if (!o.json) {
    std::printf("Every sensor calibrated from %.0f s of skeletons, the whole cell at once, against the simulator's truth "
                "(target: within %.1f deg and %.1f cm)\n",
                o.seconds, o.target_deg, o.target_cm);
  }
  for (const auto& layout : o.layouts) {
    for (const auto& scenario : o.scenarios) {
      for (const int seed : o.seeds) {
        progress("calibrating " + layout + " " + scenario + " seed " + std::to_string(seed) + " (" +
                 std::to_string(runs.size() + 1) + " of " + std::to_string(total) + ")");
        auto run = calib_sim_run(o, layout, scenario, seed);
        progress.done(false);
        within += run["within_target"].get<bool>() ? 1 : 0;
        if (run.contains("max_rotation_error_deg")) {
          worst_deg = std::max(worst_deg, run["max_rotation_error_deg"].get<double>());
          worst_cm = std::max(worst_cm, run["max_translation_error_cm"].get<double>());
        }
        if (!o.json) {
          std::printf("%-10s %-5s seed %d: ", layout.c_str(), scenario.c_str(), seed);
          if (run.contains("error")) {
            std::printf("FAILED: %s\n", run["error"].get<std::string>().c_str());
          } else {
            for (const auto& s : run["sensors"]) {
              if (!s["placed"].get<bool>()) std::printf(" %s not placed;", s["sensor"].get<std::string>().c_str());
              else std::printf(" %s %.2f deg %.1f cm%s;", s["sensor"].get<std::string>().c_str(),
                               s["rotation_error_deg"].get<double>(), s["translation_error_cm"].get<double>(),
                               s["ambiguous"].get<bool>() ? " (ambiguous)" : "");
            }
            std::printf(" %s\n", run["within_target"].get<bool>() ? "ok" : "OUTSIDE");
          }
        }
        runs.push_back(std::move(run));
      }
    }
  }
  const nlohmann::json summary{{"runs", runs.size()}, {"within_target", within}, {"target_deg", o.target_deg},
                               {"target_cm", o.target_cm}, {"max_rotation_error_deg", worst_deg},
                               {"max_translation_error_cm", worst_cm}};
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"summary", summary}, {"runs", runs}}.dump(2).c_str());
  } else {
    std::printf("%zu of %zu runs with every sensor within target; worst %.2f deg, %.1f cm\n", within, runs.size(), worst_deg,
                worst_cm);
  }
  return within == runs.size() ? 0 : 1;
}

}  // namespace skelgraph::cli::calib_cmd
