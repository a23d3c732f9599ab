#include "skelgraph/eval/sim_run.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "skelgraph/depth/depth_image.hpp"
#include "skelgraph/depth_tracker/sim_depth.hpp"
#include "skelgraph/eval/report.hpp"

namespace skelgraph::eval {

SimRun run_simulation(const sim::SimConfig& cfg, const OfflineOptions& eo, const SimSource& source,
                      const std::function<void(const std::string&)>& progress) {
  const auto say = [&](const std::string& text) {
    if (progress) progress(text);
  };
  if (source.kind != "tracker" && source.kind != "depth" && source.kind != "depth-merged")
    throw std::invalid_argument("source '" + source.kind + "': expected tracker, depth or depth-merged");
  const auto& scenario = cfg.scenario.name;
  std::map<std::string, Eigen::Isometry3d> poses;
  for (const auto& s : cfg.sensors) poses[s.id] = s.world_from_sensor();
  SimRun run;
  if (source.kind == "tracker") {
    sim::Simulation sim(cfg);
    std::vector<std::string> ids;
    for (const auto& s : cfg.sensors) ids.push_back(s.id);
    Evaluator ev(poses, ids, {}, eo);
    const double end = sim.duration() + 1.0;
    for (double until = 60.0;; until += 60.0) {
      for (auto& e : sim.advance(std::min(until, end))) {
        const auto t = cfg.epoch_ns + static_cast<std::int64_t>(std::llround(e.t * 1e9));
        ev.add({e.kind == sim::SimEvent::Kind::Truth ? TimedSkeleton::Kind::Truth : TimedSkeleton::Kind::Raw, t,
                std::move(e.skeleton)});
      }
      char text[96];
      std::snprintf(text, sizeof text, "simulating and evaluating %s: %.0f of %.0f s...", scenario.c_str(),
                    std::min(until, end), end);
      say(text);
      if (until >= end) break;
    }
    run.result = ev.finish();
    return run;
  }
  depth_tracker::SimDepthOptions dopt;
  dopt.girth = source.girth;
  dopt.merged = source.kind == "depth-merged";
  if (dopt.merged) poses["merged"] = Eigen::Isometry3d::Identity();
  dopt.intrinsics = depth::parse_depth_size(source.depth_size);
  say("rendering and tracking depth for " + scenario + "...");
  auto d = depth_tracker::track_simulated_depth(cfg, dopt);
  run.depth = {{"frames", d.frames},
               {"size", source.depth_size},
               {"girth", source.girth},
               {"render_ms_per_frame", d.frames ? 1e3 * d.render_s / d.frames : 0.0},
               {"track_ms_per_frame", d.frames ? 1e3 * d.track_s / d.frames : 0.0}};
  if (!d.events.empty()) {
    say("evaluating " + scenario + " (" + std::to_string(d.events.size()) + " events)...");
    run.result = evaluate(poses, d.events, eo);
  }
  return run;
}

nlohmann::json streams_json(const OfflineResult& r) {
  nlohmann::json streams = nlohmann::json::array();
  for (std::size_t i = 0; i < r.streams.size(); ++i) {
    streams.push_back(stream_json(r.streams[i]));
    if (i < r.fuser_stats.size()) {
      const auto& f = r.fuser_stats[i];
      streams.back()["fuser"] = {{"flips_corrected", f.flips_corrected}, {"gated", f.gated},
                                 {"tracks_merged", f.tracks_merged},     {"headings_reversed", f.headings_reversed},
                                 {"occluded_views", f.occluded_views},   {"ghost_views", f.ghost_views},
                                 {"fused", f.fused}};
    }
  }
  return streams;
}

}  // namespace skelgraph::eval
