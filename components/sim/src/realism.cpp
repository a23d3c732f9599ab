#include "skelgraph/sim/realism.hpp"

#include <cmath>
#include <stdexcept>

#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::sim {

namespace {

struct ThesisColumn {
  const char* scenario;
  double mssdk_det[kGroupCount], nite_det[kGroupCount], mssdk_err[kGroupCount], nite_err[kGroupCount];
};

// Table 5.1 (percentage of tracked position) and Table 5.2 (error, cm), per scenario column.
const ThesisColumn kThesis[] = {
    {"walk", {100, 100, 100, 100, 100, 100}, {91, 100, 100, 100, 99, 99}, {15.8, 11.2, 4.4, 7.8, 9.6, 14.8}, {10.6, 4.6, 6.7, 5.6, 9.0, 14.8}},
    {"360", {100, 100, 100, 73, 75, 76}, {99, 100, 100, 100, 90, 88}, {17.2, 14.5, 5.9, 16.8, 28.6, 47.3}, {11.8, 4.9, 6.7, 18.6, 32.0, 50.2}},
    {"hide", {100, 100, 100, 100, 100, 58}, {93, 100, 100, 100, 100, 100}, {16.1, 10.9, 3.9, 5.8, 7.6, 15.6}, {13.3, 3.2, 6.8, 7.1, 7.4, 11.0}},
    {"box", {100, 100, 100, 100, 96, 48}, {82, 100, 100, 100, 71, 70}, {13.2, 8.5, 10.1, 9.3, 6.4, 12.2}, {12.2, 10.5, 15.5, 8.7, 9.1, 15.9}},
    {"occ", {66, 67, 67, 60, 57, 47}, {83, 83, 83, 83, 59, 58}, {32.5, 31.8, 30.7, 34.6, 42.5, 52.9}, {76.2, 76.6, 82.0, 82.4, 78.5, 84.7}},
    {"sit", {100, 100, 100, 99, 74, 86}, {68, 99, 99, 99, 95, 94}, {14.8, 7.7, 7.5, 7.9, 8.7, 14.1}, {11.0, 5.7, 12.1, 9.2, 11.1, 14.2}},
    {"arms", {100, 100, 100, 96, 96, 95}, {99, 100, 100, 100, 100, 100}, {16.3, 11.2, 4.2, 6.7, 7.4, 12.7}, {13.5, 5.2, 7.5, 7.2, 8.3, 14.2}},
};

}  // namespace

Figures thesis_figures(const std::string& scenario, const std::string& profile) {
  if (profile != "mssdk" && profile != "nite") throw std::invalid_argument("the thesis has no profile '" + profile + "'");
  for (const auto& c : kThesis) {
    if (scenario != c.scenario) continue;
    Figures f;
    const bool ms = profile == "mssdk";
    for (std::size_t g = 0; g < kGroupCount; ++g) {
      f[g].detection_pct = ms ? c.mssdk_det[g] : c.nite_det[g];
      f[g].error_cm = ms ? c.mssdk_err[g] : c.nite_err[g];
    }
    return f;
  }
  throw std::invalid_argument("the thesis has no scenario '" + scenario + "'");
}

Figures simulate_figures(const std::string& scenario, const std::string& profile, const RealismOptions& opt) {
  SimConfig cfg;
  cfg.scenario.name = scenario;
  cfg.scenario.seed = opt.seed;
  cfg.scenario.repeats = opt.repeats;
  cfg.sensors = {default_sensors(1).front()};
  cfg.profile = profile;
  cfg.noise_scale = opt.noise_scale;
  cfg.truth_rate_hz = 1.0;  // truth is computed below at each frame's own time
  Simulation sim(cfg);
  const Eigen::Isometry3d world_from_sensor = cfg.sensors.front().world_from_sensor();

  eval::Accumulator acc;
  const auto events = sim.advance(sim.duration() + 1.0);
  std::uint64_t with_person = 0;
  for (const auto& e : events) {
    if (e.kind != SimEvent::Kind::Raw) continue;
    auto world = e.skeleton;
    for (auto& j : world.joints) j.position = world_from_sensor * j.position;
    acc.add(world, sim.truth_at(e.t).front());
    ++with_person;
  }
  // Frames in which the tracker reported nobody count as not detected.
  acc.add_missed(sim.frame_count(0) - std::min<std::uint64_t>(with_person, sim.frame_count(0)));
  return acc.figures();
}

bool detection_close(double sim, double thesis) { return std::abs(sim - thesis) <= 20.0; }
bool error_close(double sim, double thesis) {
  return std::abs(sim - thesis) <= 6.0 || (sim >= thesis / 2.0 && sim <= thesis * 2.0);
}

std::vector<ThesisCell> compare_with_thesis(
    const RealismOptions& opt, const std::function<void(const std::string&, const std::string&)>& on_scenario) {
  std::vector<ThesisCell> out;
  for (const auto& profile : TrackerProfile::names()) {
    std::vector<Figures> sims, refs;
    for (const auto& s : kThesisScenarios) {
      if (on_scenario) on_scenario(profile, s);
      sims.push_back(simulate_figures(s, profile, opt));
      refs.push_back(thesis_figures(s, profile));
    }
    for (std::size_t g = 0; g < kGroupCount; ++g) {
      for (std::size_t k = 0; k < sims.size(); ++k) {
        const auto& a = sims[k][g];
        const auto& b = refs[k][g];
        out.push_back({profile, kThesisScenarios[k], g, a, b, detection_close(a.detection_pct, b.detection_pct),
                       std::isfinite(a.error_cm) && error_close(a.error_cm, b.error_cm)});
      }
    }
  }
  return out;
}

}  // namespace skelgraph::sim
