#include "skelgraph/eval/fetch.hpp"

#include <filesystem>

#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/robot/arm.hpp"

namespace skelgraph::eval {

FetchRunResult run_fetch(const FetchRunOptions& o) {
  using namespace skelgraph::gesture;
  // With the build's training set-up the model is the built-in one: loaded, not trained again.
  const bool builtin = o.train_sessions == kTrainSessions && o.seed == 1 && std::filesystem::exists(builtin_model_path("sim"));
  const auto model = builtin ? load_builtin_model("sim") : train_on_sim(o.train_sessions, o.seed, sim_classifier_options());
  const auto sessions = held_out_sessions(o.sessions, o.seed);
  const auto spotted = spot_sessions(model, sessions);
  const Eigen::Vector3d base = o.world_from_base.translation();
  robot::Joints start;
  start << 0.0, -M_PI / 2, M_PI / 2, -M_PI / 2, -M_PI / 2, 0.0;
  FetchRunResult r;
  for (std::size_t n = 0; n < sessions.size(); ++n) {
    for (const auto& g : sessions[n].truth) {
      if (g.label != "point" || !g.has_target) continue;
      ++r.pointing;
      if (!robot::fetch_target(g.target, base, o.fetch)) continue;
      ++r.in_reach;
      const SpottedEvent* hit = nullptr;  // the spotter's event for this gesture (as the demo's table matches them)
      for (const auto& e : spotted[n].events) {
        if (e.label == "point" && e.has_target && e.end_ns >= g.start_ns - 500'000'000 && e.end_ns <= g.end_ns + 500'000'000) hit = &e;
      }
      if (hit == nullptr) continue;
      ++r.spotted;
      const auto hover = robot::fetch_target(hit->target, base, o.fetch);
      if (!hover) continue;
      ++r.fetched;
      robot::ArmSim arm(robot::ArmModel::ur5e(), o.world_from_base, start);
      arm.set_target(*hover, o.tool_speed);
      for (double t = 0; t < o.settle_s; t += 0.01) arm.step(0.01);
      Eigen::Vector3d miss = arm.tool_world() - g.target;
      miss.y() = 0;
      r.error_m.push_back(miss.norm());
      r.within += miss.norm() <= o.within_m ? 1 : 0;
    }
  }
  return r;
}

}  // namespace skelgraph::eval
