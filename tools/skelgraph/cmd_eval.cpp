// skelgraph eval sim: the simulator's scenarios through every fusion method
// and every single sensor, scored against ground truth in the layout of the
// thesis's Tables 5.1-5.4 (detection %, error cm per joint group). No DDS.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/eval/offline.hpp"
#include "skelgraph/sim/sim_component.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::cli {

namespace {

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json stream_json(const eval::StreamScore& s) {
  nlohmann::json groups = nlohmann::json::object();
  const auto f = s.accuracy.figures();
  for (std::size_t g = 0; g < eval::kGroupCount; ++g) {
    groups[eval::group_names()[g]] = {{"detection_pct", f[g].detection_pct}, {"error_cm", num(f[g].error_cm)}};
  }
  return {{"stream", s.name},
          {"fused", s.fused},
          {"groups", groups},
          {"mean_error_cm", num(s.accuracy.mean_error_cm())},
          {"mean_group_error_cm", num(s.accuracy.mean_group_error_cm())},
          {"upper_body_complete_pct", s.steadiness.upper_body_complete_pct()},
          {"bone_length_sd_cm", num(s.steadiness.mean_bone_sd_cm())},
          {"ticks", s.ticks},
          {"ticks_with_output", s.with_output}};
}

void print_table(const std::string& title, const eval::OfflineResult& r) {
  std::printf("\n### %s\n\n| stream |", title.c_str());
  for (const auto* g : eval::group_names()) std::printf(" %s det %% | %s err cm |", g, g);
  std::printf(" mean err cm | upper body %% | bone SD cm |\n|---|");
  for (std::size_t g = 0; g < eval::kGroupCount; ++g) std::printf("---:|---:|");
  std::printf("---:|---:|---:|\n");
  for (const auto& s : r.streams) {
    std::printf("| %s |", s.name.c_str());
    for (const auto& g : s.accuracy.figures()) std::printf(" %.1f | %.1f |", g.detection_pct, g.error_cm);
    std::printf(" %.1f | %.1f | %.2f |\n", s.accuracy.mean_error_cm(), s.steadiness.upper_body_complete_pct(),
                s.steadiness.mean_bone_sd_cm());
  }
}

struct SimEvalOptions {
  std::vector<std::string> params, scenarios{"walk", "360", "hide", "box", "occ", "sit", "arms"}, methods;
  double delay_ms = 0, max_age_ms = 100;
  bool json = false;
};

int eval_sim(const SimEvalOptions& o) {
  runtime::ParamSchema schema;
  sim::add_sim_params(schema);
  eval::OfflineOptions eo;
  if (!o.methods.empty()) {
    eo.methods.clear();
    for (const auto& m : o.methods) eo.methods.push_back(*fusion::method_from_name(m));
  }
  eo.fuser.delay_ns = static_cast<std::int64_t>(o.delay_ms * 1e6);
  eo.fuser.max_age_ns = static_cast<std::int64_t>(o.max_age_ms * 1e6);
  nlohmann::json out = nlohmann::json::array();
  if (!o.json) {
    std::printf("## Fusion against ground truth (simulator)\n\nDetection: %% of output ticks (30 Hz) a joint is reported "
                "with confidence 1; error: mean distance to truth over those, cm. Singles: each sensor alone, on the same "
                "ticks. Fusion delay %.0f ms, max sample age %.0f ms.\n",
                o.delay_ms, o.max_age_ms);
  }
  for (const auto& scenario : o.scenarios) {
    sim::SimConfig cfg;
    try {
      std::vector<runtime::RawParam> raw;
      for (const auto& p : o.params) raw.push_back(runtime::parse_param_assignment(p, "--param " + p));
      raw.push_back({"scenario", scenario, "--scenarios"});
      cfg = sim::sim_config_from(schema.resolve(raw, "eval sim"));
      sim::Simulation probe(cfg);
    } catch (const runtime::ParamError& e) {
      throw UsageError(e.what());
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    sim::Simulation sim(cfg);
    std::map<std::string, Eigen::Isometry3d> poses;
    for (const auto& s : cfg.sensors) poses[s.id] = s.world_from_sensor();
    std::vector<eval::TimedSkeleton> events;
    for (auto& e : sim.advance(sim.duration() + 1.0)) {
      const auto t = cfg.epoch_ns + static_cast<std::int64_t>(std::llround(e.t * 1e9));
      events.push_back({e.kind == sim::SimEvent::Kind::Truth ? eval::TimedSkeleton::Kind::Truth
                                                              : eval::TimedSkeleton::Kind::Raw,
                        t, std::move(e.skeleton)});
    }
    if (!o.json) std::fprintf(stderr, "\revaluating %s (%zu events)...      ", scenario.c_str(), events.size());
    const auto r = eval::evaluate(poses, events, eo);
    if (!o.json) std::fprintf(stderr, "\r%50s\r", "");
    nlohmann::json streams = nlohmann::json::array();
    for (const auto& s : r.streams) streams.push_back(stream_json(s));
    out.push_back({{"scenario", scenario}, {"sensors", cfg.sensors.size()}, {"profile", cfg.profile},
                   {"seed", cfg.scenario.seed}, {"ticks", r.ticks}, {"streams", streams}});
    if (!o.json) {
      print_table(scenario + " (" + std::to_string(cfg.sensors.size()) + " sensors, " + cfg.profile + ", seed " +
                      std::to_string(cfg.scenario.seed) + ")",
                  r);
    }
  }
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"delay_ms", o.delay_ms}, {"max_age_ms", o.max_age_ms}, {"scenarios", out}}
                            .dump(2)
                            .c_str());
  }
  return 0;
}

}  // namespace

void add_eval_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* ev = app.add_subcommand("eval", "Score single sensors and fusion methods against ground truth");
  ev->require_subcommand(1);
  auto o = std::make_shared<SimEvalOptions>();
  auto* s = ev->add_subcommand("sim", "Simulated scenarios through every fusion method (no DDS, as fast as the CPU allows)");
  s->add_option("-p,--param", o->params, "simulator parameter NAME=VALUE (as the sim component's; e.g. sensor_count=2)");
  s->add_option("--scenarios", o->scenarios, "scenarios to run (default: the thesis's seven)")->delimiter(',');
  s->add_option("--methods", o->methods, "fusion methods (default: all)")
      ->delimiter(',')
      ->check(CLI::IsMember(fusion::method_names()));
  s->add_option("--delay-ms", o->delay_ms, "fuse this far behind the newest data (room to interpolate)")->check(kNonNegative);
  s->add_option("--max-age-ms", o->max_age_ms, "samples older than this are not fused")->check(kPositive);
  s->add_flag("--json", o->json, "machine-readable results");
  s->callback([o, &run] { run = [o] { return eval_sim(*o); }; });
}

}  // namespace skelgraph::cli
