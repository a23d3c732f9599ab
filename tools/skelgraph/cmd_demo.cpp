// skelgraph demo: the main job on an embedded default graph, no files needed.

#include <cstdio>
#include <filesystem>

#include "cli.hpp"
#include "eval_sim.hpp"
#include "run_graph.hpp"
#include "skelgraph/runtime/launch_file.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

namespace {

// Same graph as bringup/demo.yaml, embedded so the demo runs from anywhere.
const char* const kDemoGraph = R"(
components:
  - name: sync
    type: sync_master
    params:
      label: demo
      tick_period_ms: 33
  - name: monitor
    type: monitor
  - name: cell
    type: sim
    params:
      scenario: point
      loop: true
  - name: fusion
    type: fusion
    params:
      method: kalman
)";

}  // namespace

void add_demo_command(CLI::App& app, GlobalOptions& g, Action& run) {
  struct Opts {
    double duration = 5.0;
    bool json = false;
    std::string report = "skelgraph-demo-report";
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("demo", "Run the demo graph (sync master + monitor + simulated cell + fusion) and print what it saw");
  cmd->add_option("--duration", o->duration, "seconds to run")->check(kPositive);
  cmd->add_flag("--json", o->json, "print the report as JSON on stdout");
  cmd->add_option("--report", o->report,
                  "where the fusion report goes (report.html + SVG figures: every thesis scenario, two simulated "
                  "sensors, single sensors and every fusion method against ground truth); empty: none");
  add_dds_options(*cmd, g);
  cmd->callback([o, &g, &run] {
    run = [o, &g] {
      std::string report_path;
      if (!o->report.empty()) {
        // Offline first (a few seconds): the seven thesis scenarios through every fusion method.
        std::fprintf(stderr, "evaluating fusion on the simulator's scenarios (report in %s)...\n", o->report.c_str());
        SimEvalOptions eo;
        eo.quiet = true;
        eo.report_dir = o->report;
        eval_sim(eo);
        report_path = (std::filesystem::path(o->report) / "report.html").string();
      }
      const auto registry = runtime::builtin_registry();
      const auto spec = runtime::parse_launch_text(kDemoGraph, "<embedded demo graph>");
      const auto components = runtime::resolve_launch(spec, registry, "");
      RunOptions ro;
      ro.duration_s = o->duration;
      ro.json = o->json;
      if (!o->json) std::printf("skelgraph demo: sync master + monitor + simulated cell + fusion on DDS domain %d (profile %s) for %.1f s\n",
                  make_config(g, &spec).domain, make_config(g, &spec).profile.c_str(), o->duration);
      return run_graph(registry, make_config(g, &spec), components, ro,
                       [o, report_path](runtime::Graph& graph, nlohmann::json& report) {
                         nlohmann::json seen;
                         for (const auto& r : graph.report()) {
                           if (r.name == "monitor") seen = r.details;
                         }
                         report["seen"] = seen;
                         if (!report_path.empty()) report["report"] = report_path;
                         if (o->json) return;
                         for (const auto& s : seen["sessions"]) {
                           std::printf(
                               "session %u '%s': START %s, %llu ticks at %.2f Hz (arrival period %.1f-%.1f ms, std %.2f ms), "
                               "%llu missing, STOP %s\n",
                               s["session_id"].get<unsigned>(), s["label"].get<std::string>().c_str(),
                               s["saw_start"].get<bool>() ? "seen" : "not seen",
                               s["ticks"].get<unsigned long long>(), s["tick_rate_hz"].get<double>(),
                               s["arrival_period_min_ms"].get<double>(), s["arrival_period_max_ms"].get<double>(),
                               s["arrival_period_std_ms"].get<double>(), s["missing_ticks"].get<unsigned long long>(),
                               s["saw_stop"].get<bool>() ? "seen" : "not seen");
                         }
                         for (const auto& [name, st] : seen["status"].items()) {
                           std::printf("component %s (%s): %s\n", name.c_str(),
                                       st["kind"].get<std::string>().c_str(), st["state"].get<std::string>().c_str());
                         }
                         if (!report_path.empty()) std::printf("fusion report: %s\n", report_path.c_str());
                       });
    };
  });
}

}  // namespace skelgraph::cli
