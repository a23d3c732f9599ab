// skelgraph demo: the main job on an embedded default graph, no files needed.
//
//  1. The live graph of bringup/demo.yaml (compiled in): a simulated
//     two-sensor cell playing the dual-sensor 360 scenario once, the sync
//     master, a monitor, the recorder, and one fusion component per method.
//  2. The session's recording scored against its ground truth: each sensor
//     alone, every method re-run offline, and what the live fusion components
//     published.
//  3. Pointing: a classifier trained on simulated sessions spots pointing in
//     others (precision, recall, latency, floor target against the truth).
//  4. The robot cell: speed-and-separation monitoring closed loop on the
//     simulated worker and a second one, judged against the truth, with its
//     timeline (true and measured separation, S_p, state).
//  5. The seven thesis scenarios through every method, offline: the thesis's
//     two sensors 90 degrees apart, then a ring of four.
//  6. One report (HTML with inline SVG, and every figure as SVG) with all of it.

#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

#include "cli.hpp"
#include "demo_graph.hpp"
#include "eval_sim.hpp"
#include "skelgraph/eval/demo_report.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"  // kTrainSessions
#include "run_graph.hpp"
#include "skelgraph/runtime/launch_file.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

namespace {

using eval::pointing_section;
using eval::robot_section;

struct DemoOptions {
  double duration = 0.0;  // 0: until the scenario ends
  bool json = false;
  std::string report = "skelgraph-demo-report";
};

void print_live(const nlohmann::json& seen) {
  for (const auto& s : seen["sessions"]) {
    std::printf("session %u '%s': START %s, %llu ticks at %.2f Hz (arrival period %.1f-%.1f ms, std %.2f ms), "
                "%llu missing, STOP %s\n",
                s["session_id"].get<unsigned>(), s["label"].get<std::string>().c_str(),
                s["saw_start"].get<bool>() ? "seen" : "not seen", s["ticks"].get<unsigned long long>(),
                s["tick_rate_hz"].get<double>(), s["arrival_period_min_ms"].get<double>(),
                s["arrival_period_max_ms"].get<double>(), s["arrival_period_std_ms"].get<double>(),
                s["missing_ticks"].get<unsigned long long>(), s["saw_stop"].get<bool>() ? "seen" : "not seen");
  }
  for (const auto& [name, st] : seen["status"].items()) {
    std::printf("component %s (%s): %s\n", name.c_str(), st["kind"].get<std::string>().c_str(),
                st["state"].get<std::string>().c_str());
  }
}

int run_demo(const DemoOptions& o, GlobalOptions& g) {
  const auto registry = runtime::builtin_registry();
  auto spec = runtime::parse_launch_text(kDemoGraph, "<embedded demo graph: bringup/demo.yaml>");
  const std::filesystem::path report_dir = o.report;
  const auto recording_dir = report_dir / "recording";
  for (auto it = spec.components.begin(); it != spec.components.end();) {
    if (it->kind != "recorder") {
      ++it;
    } else if (o.report.empty()) {
      it = spec.components.erase(it);  // no report: nothing to record for
    } else {
      auto& ps = it->params;
      ps.erase(std::remove_if(ps.begin(), ps.end(), [](const runtime::RawParam& p) { return p.key == "directory"; }), ps.end());
      it->params.push_back({"directory", recording_dir.string(), "skelgraph demo --report"});
      ++it;
    }
  }
  const auto components = runtime::resolve_launch(spec, registry, "");
  const auto config = make_config(g, &spec);
  RunOptions ro;
  ro.duration_s = o.duration;
  ro.json = false;  // one JSON document at the end, with the evaluation in it
  ro.status_every_s = o.json ? 0.0 : 5.0;
  std::fprintf(stderr,
               "[demo 1/5] live graph on DDS domain %d (profile %s): simulated two-sensor cell playing the dual-sensor "
               "360 scenario (~24 s), sync master, monitor, %s, fusion with every method (avg, sum, facing, weighted, "
               "kalman); status every 5 s\n",
               config.domain, config.profile.c_str(),
               o.report.empty() ? "no recorder (--report is empty)" : ("recorder into " + recording_dir.string()).c_str());
  nlohmann::json out;
  std::string file;
  const int rc = run_graph(registry, config, components, ro, [&](runtime::Graph& graph, nlohmann::json& report) {
    for (const auto& r : graph.report()) {
      if (r.name == "monitor") report["seen"] = r.details;
    }
    file = recorded_file(graph);
    out = report;
  });
  if (interrupted()) {  // the live graph was stopped by a signal: no report of half a session
    std::fprintf(stderr, "[demo] interrupted: the live graph stopped, no report written\n");
    return 130;
  }
  if (!o.json) print_live(out["seen"]);
  if (rc != 0) {
    std::fprintf(stderr, "skelgraph demo: a component of the live graph ended in ERROR (see above)\n");
    if (o.json) std::printf("%s\n", out.dump(2).c_str());
    return rc;
  }
  if (!o.report.empty()) {
    if (file.empty()) throw std::runtime_error("the recorder wrote no file (the sync session never started?)");
    out["recording"] = file;
    std::fprintf(stderr, "[demo 2/5] scoring the live session's recording %s against its ground truth\n", file.c_str());
    const auto live = eval_recording_section(
        file, report_dir.string(),
        "live graph: 360, 2 sensors (recorded; offline re-runs and what the live fusion components published)");
    out["live_evaluation"] = live.summary;
    std::fprintf(stderr, "[demo 3/5] pointing: the built-in classifier (trained by the build on %d simulated sessions), "
                 "spotting in 4 others\n", gesture::kTrainSessions);
    const auto pointing = pointing_section(report_dir);
    out["pointing"] = pointing.summary;
    std::fprintf(stderr, "[demo 4/5] the robot cell: speed and separation monitoring judged against the truth (offline)\n");
    const auto robot = robot_section(report_dir);
    out["robot"] = robot.summary;
    std::fprintf(stderr, "[demo 5/5] the seven thesis scenarios through every fusion method, 2 and 4 sensors (offline)\n");
    SimEvalOptions eo;
    eo.quiet = true;
    eo.layouts = {"quarters:2", "ring:4"};  // the thesis's pair, then four sensors round the person
    eo.report_dir = report_dir.string();
    eo.extra_html = live.html + pointing.html + robot.html;
    eval_sim(eo);
    out["report"] = (report_dir / "report.html").string();
    if (!o.json) {
      std::printf("\nlive session (%s), mean error of joints at confidence 1 against ground truth:\n", file.c_str());
      for (const auto& s : live.summary["streams"]) {
        const auto& e = s["mean_error_cm"];
        std::printf("  %-16s %s cm, upper body complete %.1f %% of ticks\n", s["stream"].get<std::string>().c_str(),
                    e.is_number() ? std::to_string(e.get<double>()).substr(0, 5).c_str() : "-",
                    s["upper_body_complete_pct"].get<double>());
      }
      const auto& p = out["pointing"];
      std::printf("pointing in held-out simulated sessions: F1 %.2f (%d of %d found, %d false), sent %.0f ms after the "
                  "hold began, floor target %.1f cm from the true one (median)\n",
                  p["f1"].get<double>(), p["true_positive"].get<int>(), p["truth"].get<int>(), p["false_positive"].get<int>(),
                  1e3 * p["median_latency_from_hold_s"].get<double>(), 100 * p["median_target_error_m"].get<double>());
      std::printf("report: %s\n", out["report"].get<std::string>().c_str());
      std::printf("the recording is also a 3-D scene for Foxglove/Lichtblick (open it, 3D panel, display frame 'cell'): %s\n",
                  file.c_str());
    }
  }
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

}  // namespace

void add_demo_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto o = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand(
      "demo",
      "The main job: a simulated two-sensor cell through the live graph (sync, recorder, fusion with every method), "
      "the recording scored against ground truth, the seven thesis scenarios offline, one report");
  cmd->add_option("--duration", o->duration, "stop the live graph after this many seconds (default: when the scenario ends)")
      ->check(kNonNegative);
  cmd->add_flag("--json", o->json, "print the results as JSON on stdout");
  cmd->add_option("--report", o->report,
                  "report directory: report.html, SVG figures, and the live session's recording under recording/; "
                  "empty: live graph only");
  add_dds_options(*cmd, g);
  cmd->callback([o, &g, &run] { run = [o, &g] { return run_demo(*o, g); }; });
}

}  // namespace skelgraph::cli
