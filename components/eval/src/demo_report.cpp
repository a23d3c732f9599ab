#include "skelgraph/eval/demo_report.hpp"

#include <cstdio>
#include <fstream>
#include <vector>

#include "skelgraph/eval/safety.hpp"
#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/report/report.hpp"

namespace skelgraph::eval {

// Pointing on simulated sessions: the built-in model the live graph uses
// (trained by the build as `gesture sim` trains), spotting in 4 held-out ones and score against the truth; the false alarms in
// 4 sessions of each scenario where nobody gestures; and recall against false alarms at other operating points.
ReportSection pointing_section(const std::filesystem::path& report_dir) {
  using namespace gesture;
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
  const auto quiet_runs = quiet_sessions(quiet_scenarios(), 4, 1);
  const auto quiet = spot_quiet(model, quiet_runs);
  const auto curve = operating_curve(model, sessions, quiet_runs, sim_spotter_options());
  std::vector<report::Series> lines;
  nlohmann::json curve_json = nlohmann::json::array();
  std::string curve_rows;
  for (const auto& p : curve) {
    char name[64], row[300];
    std::snprintf(name, sizeof name, "confirm %.2g s", p.confirm);
    if (lines.empty() || lines.back().name != name) lines.push_back({name, {}, {}});
    lines.back().x.push_back(p.false_per_hour);
    lines.back().y.push_back(p.recall);
    curve_json.push_back({{"min_confidence", p.min_confidence}, {"confirm_s", p.confirm}, {"recall", p.recall},
                          {"false_per_hour", p.false_per_hour}});
    std::snprintf(row, sizeof row, "<tr><td>%.2f</td><td>%.2f s</td><td>%.3f</td><td>%.1f</td><td>%.0f ms</td></tr>\n",
                  p.min_confidence, p.confirm, p.recall, p.false_per_hour, 1e3 * p.median_latency_hold_s);
    curve_rows += row;
  }
  const auto curve_plot = report::line_plot("Pointing: recall against false events per hour (operating points)",
                                            "false pointing events per hour of work without gestures", "recall", lines);
  std::ofstream(report_dir / "pointing_curve.svg") << curve_plot;
  std::string by;
  for (const auto& q : quiet.scenarios) {
    const auto it = q.events.find("point");
    by += (by.empty() ? "" : ", ") + q.name + " " + std::to_string(it == q.events.end() ? 0 : it->second);
  }
  ReportSection s;
  s.summary = to_json(r);
  s.summary["false_points_per_hour"] = quiet.per_hour("point");
  s.summary["quiet_hours"] = quiet.hours;
  s.summary["operating_curve"] = curve_json;
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
           rows + "</table>\n<p>The operating point is chosen at spotting time (the <code>gesture</code> component's "
           "<code>min_confidence</code> and <code>confirm_s</code>): each point spots the same sessions again.</p>\n" +
           curve_plot + "\n<table><tr><th>min_confidence</th><th>confirm</th><th>recall</th><th>false events per "
           "hour</th><th>latency from the hold</th></tr>\n" + curve_rows + "</table>\n";
  return s;
}

// The robot cell (bringup/robot_cell.yaml's), two workers, closed loop and
// judged against the truth (eval/safety.hpp), with its timeline.
ReportSection robot_section(const std::filesystem::path& report_dir) {
  auto o = robot_cell_options();
  o.sim.scenario.people = 2;
  o.sim.scenario.repeats = 2;
  o.trace_period_s = 0.1;
  const auto r = run_safety(o);
  ReportSection s;
  s.summary = {{"seconds", r.seconds},
               {"missed_steps", r.missed_steps},
               {"intrusions", r.intrusions},
               {"time_to_stop_ms_max", quantile(r.time_to_stop_ms, 1.0)},
               {"stops", r.stops},
               {"stop_pct", r.share_pct(r.stop_steps)},
               {"unnecessary_stop_pct", r.share_pct(r.unnecessary_steps)},
               {"reaction_ms_p50", quantile(r.reaction_ms, 0.5)},
               {"reaction_ms_p99", quantile(r.reaction_ms, 0.99)},
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
                r.share_pct(r.stop_steps), r.share_pct(r.unnecessary_steps), quantile(r.reaction_ms, 0.5),
                quantile(r.reaction_ms, 0.99));
  s.html = std::string(head) + plot + "\n" + states + "\n";
  return s;
}

}  // namespace skelgraph::eval
