#pragma once
// `skelgraph eval sim`, also run by `skelgraph demo`.

#include <string>
#include <vector>

namespace skelgraph::cli {

struct SimEvalOptions {
  // -p NAME=VALUE for the simulator; the scenarios to run; fusion methods (empty: all)
  std::vector<std::string> params, scenarios{"walk", "360", "hide", "box", "occ", "sit", "arms"}, methods;
  double delay_ms = 0, max_age_ms = 100;
  bool json = false;
  bool quiet = false;  // nothing on stdout (progress still on stderr)
  std::string report_dir;
};

// Prints the tables (Markdown, or JSON with `json`), writes the report when report_dir is set.
int eval_sim(const SimEvalOptions& o);

}  // namespace skelgraph::cli
