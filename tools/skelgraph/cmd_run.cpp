// skelgraph run TYPE [--name N] [-p key=value]...: one component, no launch file.

#include "cli.hpp"
#include "run_graph.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

void add_run_command(CLI::App& app, GlobalOptions& g, Action& run) {
  struct Opts {
    std::string kind;
    std::string name;
    std::vector<std::string> params;
    RunOptions run;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("run", "Run one component in this process, parameters from the command line");
  cmd->add_option("type", o->kind, "component type (see `skelgraph components`)")->required();
  cmd->add_option("--name", o->name, "component name (default: the type)");
  cmd->add_option("-p,--param", o->params, "parameter as KEY=VALUE (repeatable; lists as a,b,c)");
  add_run_options(*cmd, o->run);
  add_dds_options(*cmd, g);
  cmd->callback([o, &g, &run] {
    run = [o, &g] {
      const auto registry = runtime::builtin_registry();
      const auto* entry = registry.find(o->kind);
      if (entry == nullptr) {
        throw UsageError("unknown component type '" + o->kind + "' (known: " + registry.kinds_text() + ")");
      }
      const auto name = o->name.empty() ? o->kind : o->name;
      runtime::ResolvedComponent c;
      c.name = name;
      c.kind = o->kind;
      try {
        std::vector<runtime::RawParam> raw;
        for (const auto& p : o->params) raw.push_back(runtime::parse_param_assignment(p, "--param " + p));
        c.params = entry->info.params.resolve(raw, "component '" + name + "' (" + o->kind + ")");
      } catch (const runtime::ParamError& e) {
        throw UsageError(e.what());
      }
      return run_graph(registry, make_config(g), {c}, o->run, nullptr);
    };
  });
}

}  // namespace skelgraph::cli
