// skelgraph eval sim: the simulator's scenarios through every fusion method
// and every single sensor (eval/sim_run.hpp), scored against ground truth in
// the layout of the thesis's Tables 5.1-5.4 (detection %, error cm per joint
// group). No DDS.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "eval_sim.hpp"
#include "skelgraph/eval/report.hpp"
#include "skelgraph/eval/recording.hpp"  // offline_options
#include "skelgraph/eval/sim_run.hpp"
#include "skelgraph/report/report.hpp"

namespace skelgraph::cli {

namespace {

}  // namespace

// The printed table of every stream (Markdown).
void print_table(const std::string& title, const eval::OfflineResult& r) {
  const bool at_use = eval::has_at_use(r);
  std::printf("\n### %s\n\n| stream |", title.c_str());
  for (const auto* g : eval::group_names()) std::printf(" %s det %% | %s err cm |", g, g);
  std::printf(" mean err cm |%s offsets removed cm | upper body %% | bone SD cm |\n|---|", at_use ? " at use cm |" : "");
  for (std::size_t g = 0; g < eval::kGroupCount; ++g) std::printf("---:|---:|");
  std::printf("---:|%s---:|---:|---:|\n", at_use ? "---:|" : "");
  for (const auto& s : r.streams) {
    std::printf("| %s |", s.name.c_str());
    for (const auto& g : s.accuracy.figures()) std::printf(" %.1f | %.1f |", g.detection_pct, g.error_cm);
    std::printf(" %.1f |", s.accuracy.mean_error_cm());
    if (at_use) std::printf(" %.1f |", s.at_use.mean_error_cm());
    std::printf(" %.1f | %.1f | %.2f |\n", s.compensated.mean_error_cm(), s.steadiness.upper_body_complete_pct(),
                s.steadiness.mean_bone_sd_cm());
  }
}



int eval_sim(const SimEvalOptions& o) {
  eval::OfflineOptions eo = eval::offline_options(o.methods, o.delay_ms, o.max_age_ms);
  eo.fuser.predict_ns = static_cast<std::int64_t>(o.predict_ms * 1e6);
  eo.use_delay_ns = static_cast<std::int64_t>(o.use_delay_ms * 1e6);
  eo.trace = !o.report_dir.empty();
  std::string html;
  if (eo.trace) std::filesystem::create_directories(o.report_dir);
  nlohmann::json out = nlohmann::json::array();
  std::string csv = eval::csv_header();
  if (!o.json && !o.quiet) {
    std::printf("## Fusion against ground truth (simulator)\n\nDetection: %% of output ticks (30 Hz) a joint is reported "
                "with confidence 1; error: mean distance to truth over those, cm. Singles: each sensor alone, on the same "
                "ticks. 'Offsets removed': after the first 5 s, each stream's constant per-joint offsets (learnt in its own "
                "body frame over those 5 s) subtracted. Fusion delay %.0f ms, max sample age %.0f ms.\n",
                o.delay_ms, o.max_age_ms);
    if (o.use_delay_ms > 0) {
      std::printf("'At use': the mean error against where the person is %.0f ms after each output (kalman predicting "
                  "%.0f ms).\n",
                  o.use_delay_ms, o.predict_ms);
    }
  }
  // Each layout (--layouts LAYOUT:N, else the -p parameters alone) with every scenario.
  std::vector<std::string> layouts = o.layouts.empty() ? std::vector<std::string>{""} : o.layouts;
  for (const auto& layout : layouts) {
  std::vector<std::string> params = o.params;
  std::string prefix;  // of section titles, file names and CSV scenario labels
  if (!layout.empty()) {
    const auto colon = layout.find(':');
    if (colon == std::string::npos) throw UsageError("--layouts: '" + layout + "' is not LAYOUT:SENSORS, e.g. ring:4");
    params.erase(std::remove_if(params.begin(), params.end(),
                                [](const std::string& a) { return a.rfind("layout=", 0) == 0 || a.rfind("sensor_count=", 0) == 0; }),
                 params.end());  // (the layout's own take their place)
    params.push_back("layout=" + layout.substr(0, colon));
    params.push_back("sensor_count=" + layout.substr(colon + 1));
    prefix = layout.substr(0, colon) + "_" + layout.substr(colon + 1) + "_";
    const auto check = sim_config(params, "eval sim --layouts", {});
    (void)check;  // (a bad layout or count is a usage error before anything runs)
    if (!o.json && !o.quiet) std::printf("\n## Layout %s: %zu sensors\n", layout.substr(0, colon).c_str(), check.sensors.size());
    if (eo.trace) html += "<h1>Layout " + report::html_escape(layout) + "</h1>\n";
  }
  for (const auto& scenario : o.scenarios) {
    const sim::SimConfig cfg = sim_config(params, "eval sim", {{"scenario", scenario, "--scenarios"}});
    Progress progress(!o.json && !o.quiet);
    eval::SimRun run;
    try {
      run = eval::run_simulation(cfg, eo, {o.source, o.depth_size, o.girth}, [&](const std::string& text) { progress(text); });
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    const auto& r = run.result;
    const auto& depth_info = run.depth;
    progress.done(false);
    if (o.quiet) std::fprintf(stderr, "evaluated %s: %zu streams over %llu ticks\n", scenario.c_str(), r.streams.size(),
                              static_cast<unsigned long long>(r.ticks));
    const auto streams = eval::streams_json(r);
    out.push_back({{"scenario", scenario}, {"sensors", cfg.sensors.size()}, {"profile", cfg.profile},
                   {"seed", cfg.scenario.seed}, {"ticks", r.ticks}, {"streams", streams}, {"source", o.source}});
    if (!layout.empty()) out.back()["layout"] = layout;
    if (!depth_info.is_null()) out.back()["depth"] = depth_info;
    const std::string title =
        scenario + " (" + std::to_string(cfg.sensors.size()) + " sensors, " +
        (o.source != "tracker" ? o.source + " tracker on " + o.depth_size + " images" : cfg.profile) + ", seed " +
        std::to_string(cfg.scenario.seed) + ")";
    if (!depth_info.is_null() && !o.json && !o.quiet) {
      std::printf("\n%llu depth images: rendering %.1f ms, tracking %.1f ms per image (one thread)\n",
                  static_cast<unsigned long long>(depth_info["frames"].get<std::uint64_t>()),
                  depth_info["render_ms_per_frame"].get<double>(), depth_info["track_ms_per_frame"].get<double>());
    }
    if (!o.json && !o.quiet) {
      print_table(title, r);
      if (cfg.scenario.people > 1) {  // several people: did each keep their id?
        std::printf("\nId switches per person-minute (a true person's output changing id):");
        for (const auto& s : r.streams) std::printf(" %s %.2f;", s.name.c_str(), s.id_switches_per_person_minute());
        std::printf("\n");
      }
    }
    if (eo.trace) html += eval::report_section(o.report_dir, prefix + scenario, title, r, "right_hand");
    csv += eval::csv_rows(prefix + scenario, r);
  }
  }
  if (!o.csv.empty()) eval::write_text_file(o.csv, csv);
  if (eo.trace) eval::write_text_file(std::filesystem::path(o.report_dir) / "results.csv", csv);
  if (eo.trace) {
    const auto path = eval::write_report_page(o.report_dir, "skelgraph: fusion against ground truth",
                                        o.extra_html + html);
    if (!o.json && !o.quiet) std::printf("\nreport: %s\n", path.c_str());
  }
  if (o.json && !o.quiet) {
    std::printf("%s\n", nlohmann::json{{"delay_ms", o.delay_ms},
                                       {"max_age_ms", o.max_age_ms},
                                       {"predict_ms", o.predict_ms},
                                       {"use_delay_ms", o.use_delay_ms},
                                       {"scenarios", out}}
                            .dump(2)
                            .c_str());
  }
  return 0;
}

}  // namespace skelgraph::cli
