// skelgraph launch FILE [--host NAME] [--set COMPONENT.KEY=VALUE]... [--duration S]

#include <cstdio>
#include <cstdlib>

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
    std::vector<std::string> set;
    RunOptions run;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("launch", "Run the components a launch file lists (for one host) in this process");
  cmd->add_option("file", o->file, "launch file (YAML), e.g. bringup/sync.yaml")->required();
  cmd->add_option("--host", o->host, "run only the components listed for this host");
  cmd->add_option("--set", o->set, "a parameter over the file's: COMPONENT.KEY=VALUE (repeatable; a list as a,b)");
  add_run_options(*cmd, o->run);
  add_dds_options(*cmd, g);
  cmd->callback([o, &g, &run] {
    run = [o, &g] {
      const auto registry = runtime::builtin_registry();
      auto spec = runtime::parse_launch_file(o->file);
      runtime::set_launch_params(spec, o->set);
      const auto components = runtime::resolve_launch(spec, registry, o->host);
      auto config = make_config(g, &spec);
      // The launch file's host name is this process's host in status and sync acks (unless SKELGRAPH_HOST says).
      if (!o->host.empty() && std::getenv("SKELGRAPH_HOST") == nullptr) config.host = o->host;
      return run_graph(registry, config, components, o->run, nullptr);
    };
  });
}

}  // namespace skelgraph::cli
