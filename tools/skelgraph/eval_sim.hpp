#pragma once
// `skelgraph eval sim`, also run by `skelgraph demo`.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/eval/offline.hpp"

namespace skelgraph::cli {

struct SimEvalOptions {
  // -p NAME=VALUE for the simulator; the scenarios to run; fusion methods (empty: all)
  std::vector<std::string> params, scenarios{"walk", "360", "hide", "box", "occ", "sit", "arms"}, methods;
  // Sensor layouts "LAYOUT:SENSORS" (e.g. ring:4), each run with every scenario; empty: the -p parameters alone.
  std::vector<std::string> layouts;
  double delay_ms = 0, max_age_ms = 100;
  double predict_ms = 0;    // kalman: predict each joint this far past the fusion time
  double use_delay_ms = 0;  // score every stream against the truth this long after each output (time of use)
  // Where the raw skeletons come from: "tracker" (the simulator's tracker
  // model) or "depth" (rendered depth images through the open depth tracker).
  std::string source = "tracker";
  std::string depth_size = "320x240";
  double girth = 1.1;  // depth: the simulated people's build against the tracker's standard model
  bool json = false;
  bool quiet = false;  // nothing on stdout (progress still on stderr)
  std::string report_dir;
  std::string csv;         // also write the tables as CSV to this file
  std::string extra_html;  // report sections placed before the scenarios' (the demo's live recording)
};

// Prints the tables (Markdown, or JSON with `json`), writes the report when report_dir is set.
int eval_sim(const SimEvalOptions& o);

// One run's table of every stream (Markdown), under `### title`.
void print_table(const std::string& title, const eval::OfflineResult& r);

// A recording scored as `skelgraph eval recording` does (single sensors, every
// method re-run offline, and the live fusion streams it recorded), for a report:
// its figures go to report_dir, its section's HTML and the figures as JSON come back.
struct RecordingReport {
  nlohmann::json summary;
  std::string html;
};
RecordingReport eval_recording_section(const std::string& file, const std::string& report_dir, const std::string& title);

}  // namespace skelgraph::cli
