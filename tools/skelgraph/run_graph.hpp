#pragma once
// Runs a resolved graph in this process until a signal or the duration ends,
// printing a status line per component at start, on request and at the end.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/launch_file.hpp"

namespace CLI {
class App;
}

namespace skelgraph::cli {

struct RunOptions {
  double duration_s = 0.0;      // 0: until a signal
  double status_every_s = 0.0;  // 0: only at start and end
  bool json = false;            // final report as JSON on stdout
  std::string auth_stall;       // "NAME@SECONDS": component NAME counts as stuck in authentication then (tests of the restart)
};

// Adds --duration, --status-every and --json to a command that runs a graph.
void add_run_options(CLI::App& cmd, RunOptions& options);

// `extra_report` (optional) adds to the final JSON / text after the graph stopped.
int run_graph(const runtime::ComponentRegistry& registry, const runtime::DdsConfig& config,
              const std::vector<runtime::ResolvedComponent>& components, const RunOptions& options,
              const std::function<void(runtime::Graph&, nlohmann::json&)>& extra_report);

// Components given by type and parameters as text (like `skelgraph run`):
// resolved against the built-in registry (bad parameters are a UsageError)
// and run with run_graph on the command line's DDS settings.
struct ComponentRun {
  std::string name, kind;
  std::vector<runtime::RawParam> raw;
};
struct GlobalOptions;
int run_components(GlobalOptions& g, const std::vector<ComponentRun>& list, const RunOptions& options,
                   const std::function<void(runtime::Graph&, nlohmann::json&)>& extra_report = nullptr);

// The first recording a recorder component of the graph wrote, if any.
std::string recorded_file(const runtime::Graph& graph);

}  // namespace skelgraph::cli
