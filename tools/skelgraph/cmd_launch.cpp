// skelgraph launch FILE [--host NAME] [--duration S]

#include <cstdio>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "cli.hpp"
#include "run_graph.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

void add_launch_command(CLI::App& app, GlobalOptions& g, Action& run) {
  struct Opts {
    std::string file;
    std::string host;
    double duration = 0.0;
    double status_every = 0.0;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("launch", "Run the components a launch file lists (for one host) in this process");
  cmd->add_option("file", o->file, "launch file (YAML), e.g. bringup/sync.yaml")->required();
  cmd->add_option("--host", o->host, "run only the components listed for this host");
  cmd->add_option("--duration", o->duration, "stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(kNonNegative);
  cmd->add_option("--status-every", o->status_every, "print each component's status line every S seconds")
      ->check(kNonNegative);
  cmd->add_flag("--json", o->json, "print the final report as JSON on stdout");
  add_dds_options(*cmd, g);
  cmd->callback([o, &g, &run] {
    run = [o, &g] {
      runtime::ComponentRegistry registry;
      runtime::register_builtin_components(registry);
      const auto spec = runtime::parse_launch_file(o->file);
      const auto components = runtime::resolve_launch(spec, registry, o->host);
      RunOptions ro;
      ro.duration_s = o->duration;
      ro.status_every_s = o->status_every;
      ro.json = o->json;
      return run_graph(registry, make_config(g, &spec), components, ro, nullptr);
    };
  });
}

}  // namespace skelgraph::cli
