// skelgraph components: the component types compiled in, with their parameters.

#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

void add_components_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto json = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("components", "List the component types launch files can use, with parameters");
  cmd->add_flag("--json", *json, "print JSON");
  cmd->callback([json, &run] {
    run = [json] {
      const auto registry = runtime::builtin_registry();
      nlohmann::json out = nlohmann::json::array();
      for (const auto& kind : registry.kinds()) {
        const auto& info = registry.find(kind)->info;
        nlohmann::json params = nlohmann::json::array();
        if (!*json) std::printf("%s\n  %s\n", kind.c_str(), info.description.c_str());
        for (const auto& p : info.params.specs()) {
          const auto def = p.default_value ? runtime::format_value(*p.default_value) : std::string("(required)");
          params.push_back({{"name", p.name}, {"type", runtime::to_string(p.type)}, {"default", def},
                            {"description", p.description}});
          if (!*json) {
            std::printf("    %-20s %-8s %-10s %s\n", p.name.c_str(), runtime::to_string(p.type), def.c_str(),
                        p.description.c_str());
          }
        }
        out.push_back({{"kind", kind}, {"description", info.description}, {"params", params}});
      }
      if (*json) std::printf("%s\n", out.dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace skelgraph::cli
