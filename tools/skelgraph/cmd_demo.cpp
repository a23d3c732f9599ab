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
#include "skelgraph/report/report.hpp"
#include "skelgraph/eval/safety.hpp"
#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"
#include "run_graph.hpp"
#include "skelgraph/runtime/launch_file.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

namespace {

struct Section {
  nlohmann::json summary;
  std::string html;
};

// Pointing on simulated sessions: the built-in model the live graph uses
// (trained by the build as `gesture sim` trains), spotting in 4 held-out ones and score against the truth; and the false alarms in a
// session of each scenario where nobody gestures.
Section pointing_section() {
  using namespace skelgraph::gesture;
  const auto model = load_builtin_model("sim");
  const auto sessions = held_out_sessions(4, 1);
  std::vector<SpottingReport> reports;
  std::string rows;
  const auto spotted = spot_sessions(model, sessions);
  for (std::size_t n = 0; n < sessions.size(); ++n) {
    reports.push_back(spotted[n].report);
    for (const auto& g : sessions[n].truth) {
      if (g.label != "point") continue;
      const SpottedEvent* hit = nullptr;
      for (const auto& e : spotted[n].events)
        if (e.end_ns >= g.start_ns - 500'000'000 && e.end_ns <= g.end_ns + 500'000'000) hit = &e;
      char sent[32] = "missed", where[64] = "-", error[32] = "-", buf[400];
      if (hit) std::snprintf(sent, sizeof sent, "%.0f ms", 1e3 * static_cast<double>(hit->end_ns - g.hold_ns) * 1e-9);
      if (hit && hit->has_target) {
        std::snprintf(where, sizeof where, "(%.2f, %.2f)", hit->target.x(), hit->target.z());
        std::snprintf(error, sizeof error, "%.1f cm", 100 * (hit->target - g.target).norm());
      }
      std::snprintf(buf, sizeof buf, "<tr><td>%zu</td><td>%.1f</td><td>(%.2f, %.2f)</td><td>%s</td><td>%s</td><td>%s</td></tr>\n",
                    n + 1, static_cast<double>(g.start_ns) * 1e-9, g.target.x(), g.target.z(), sent, where, error);
      rows += buf;
    }
  }
  const auto r = combine(reports);
  const auto quiet = spot_quiet(model, quiet_sessions(quiet_scenarios(), 1, 1));
  std::string by;
  for (const auto& q : quiet.scenarios) {
    const auto it = q.events.find("point");
    by += (by.empty() ? "" : ", ") + q.name + " " + std::to_string(it == q.events.end() ? 0 : it->second);
  }
  Section s;
  s.summary = to_json(r);
  s.summary["false_points_per_hour"] = quiet.per_hour("point");
  s.summary["quiet_hours"] = quiet.hours;
  char head[1200];
  std::snprintf(head, sizeof head,
                "<h2>Pointing (gesture spotting on the fused stream)</h2>\n<p>A classifier trained on %d simulated "
                "sessions of the point scenario (and against its own false alarms in sessions where nobody points) spots "
                "pointing in 4 others it never saw: precision %.2f, recall %.2f, "
                "F1 %.2f, <b>%.0f false pointing events per hour</b> of work without gestures (%.0f s of the simulator's "
                "scenarios: %s); sent a median %.0f ms after the arm came to rest pointing (the ray gathered over the hold); the ray meets the floor a median "
                "%.1f cm from the true target (ray direction %.1f&deg; off).</p>\n",
                kTrainSessions, r.precision, r.recall, r.f1, quiet.per_hour("point"), quiet.hours * 3600.0, by.c_str(),
                1e3 * r.median_latency_hold_s, 100 * r.median_target_error_m, r.median_ray_error_deg);
  s.html = std::string(head) +
           "<table><tr><th>session</th><th>gesture at (s)</th><th>true target x, z (m)</th><th>sent after the hold "
           "began</th><th>spotted target x, z (m)</th><th>error</th></tr>\n" +
           rows + "</table>\n";
  return s;
}

// The robot cell (bringup/robot_cell.yaml's), two workers, closed loop and
// judged against the truth (eval/safety.hpp), with its timeline.
Section robot_section(const std::filesystem::path& report_dir) {
  auto o = eval::robot_cell_options();
  o.sim.scenario.people = 2;
  o.sim.scenario.repeats = 2;
  o.trace_period_s = 0.1;
  const auto r = eval::run_safety(o);
  const auto pct = [&](std::uint64_t n) { return r.steps ? 100.0 * static_cast<double>(n) / static_cast<double>(r.steps) : 0.0; };
  Section s;
  s.summary = {{"seconds", r.seconds},
               {"missed_steps", r.missed_steps},
               {"intrusions", r.intrusions},
               {"time_to_stop_ms_max", eval::quantile(r.time_to_stop_ms, 1.0)},
               {"stops", r.stops},
               {"stop_pct", pct(r.stop_steps)},
               {"unnecessary_stop_pct", pct(r.unnecessary_steps)},
               {"reaction_ms_p50", eval::quantile(r.reaction_ms, 0.5)},
               {"reaction_ms_p99", eval::quantile(r.reaction_ms, 0.99)},
               {"task_points_reached", r.task_points_reached}};
  report::Series truth{"true separation", {}, {}}, seen{"measured separation", {}, {}}, sp{"S_p (monitor)", {}, {}};
  report::Strip run{"run", {}, {}}, reduced{"reduced", {}, {}}, stop{"stop", {}, {}};
  for (const auto& p : r.trace) {
    for (auto* x : {&truth, &seen, &sp}) x->x.push_back(p.t);
    truth.y.push_back(p.true_m);
    seen.y.push_back(p.seen_m);
    sp.y.push_back(p.protective_m);
    for (auto* x : {&run, &reduced, &stop}) x->x.push_back(p.t);
    run.on.push_back(p.state == robot::SafetyState::Run);
    reduced.on.push_back(p.state == robot::SafetyState::Reduced);
    stop.on.push_back(p.state == robot::SafetyState::ProtectiveStop);
  }
  const auto plot = report::line_plot("Closest person part to the arm", "time (s)", "m", {truth, seen, sp});
  const auto states = report::timeline("The monitor's state", {run, reduced, stop}, 760, "green: in that state");
  std::ofstream(report_dir / "robot_separation.svg") << plot;
  std::ofstream(report_dir / "robot_state.svg") << states;
  char head[1200];
  std::snprintf(head, sizeof head,
                "<h2>Robot cell (speed and separation monitoring, judged against the truth)</h2>\n<p>A UR5e-class arm "
                "works round four points at 0.5 m/s while a worker walks up to it, reaches in and walks past, and a "
                "second worker circles through its reach; four simulated sensors, kalman fusion, the separation "
                "monitor every 10 ms (ISO/TS 15066's formula; not a certified safety function), the arm obeying after "
                "10 ms. Over %.0f s: %llu steps in which the arm could move although the true separation was under the "
                "true S_p (target 0); %llu protective stops, the arm stopped %.0f %% of the time, needlessly (the truth left "
                "room for a useful speed) %.0f %% of the time; reaction time (the data's age, the trackers' 50 ms in it, plus the command "
                "latency) median %.0f ms, p99 %.0f ms. <code>skelgraph eval safety</code> runs an hour of it.</p>\n",
                r.seconds, static_cast<unsigned long long>(r.missed_steps), static_cast<unsigned long long>(r.stops),
                pct(r.stop_steps), pct(r.unnecessary_steps), eval::quantile(r.reaction_ms, 0.5),
                eval::quantile(r.reaction_ms, 0.99));
  s.html = std::string(head) + plot + "\n" + states + "\n";
  return s;
}

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
    const auto pointing = pointing_section();
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
