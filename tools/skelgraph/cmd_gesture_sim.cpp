// skelgraph gesture sim: the built-in pointing model's training and its
// measure on held-out simulated sessions and sessions without gestures.

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/clip_spotting.hpp"
#include "skelgraph/gesture/dataset.hpp"
#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/gesture/stream_spotting.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/sim/scenario.hpp"

#include "cmd_gesture.hpp"

namespace skelgraph::cli::gesture_cmd {

namespace {

nlohmann::json event_json(const SpottedEvent& e) {
  nlohmann::json j{{"label", e.label},
                   {"person_id", e.person_id},
                   {"start_s", static_cast<double>(e.start_ns) * 1e-9},
                   {"end_s", static_cast<double>(e.end_ns) * 1e-9},
                   {"log_likelihood", e.log_likelihood},
                   {"confidence", e.confidence}};
  if (e.has_ray) {
    j["arm"] = e.arm;
    j["ray_origin"] = {e.ray_origin.x(), e.ray_origin.y(), e.ray_origin.z()};
    j["ray_direction"] = {e.ray_direction.x(), e.ray_direction.y(), e.ray_direction.z()};
    j["straightness"] = e.straightness;
    if (std::isfinite(e.lean_m)) j["lean_m"] = e.lean_m;
  }
  if (e.has_target) {
    j["target"] = {e.target.x(), e.target.y(), e.target.z()};
    j["target_name"] = e.target_name;
  }
  return j;
}

}  // namespace

// Simulated sessions: train on some, spot on others, score against the truth.
int gesture_sim(const GestureOptions& o) {
  auto c = classifier_options(o);
  c.trimmed = sim_classifier_options().trimmed;
  Progress line;
  const auto progress = [&](const char* what, int done, int total) {
    line(std::string(what) + ": session " + std::to_string(done) + "/" + std::to_string(total), done == total);
  };
  std::size_t clips = 0;
  const auto model = train_on_sim(o.train_sessions, o.seed, c, &clips,
                                  [&](int d, int t) { progress("simulating and fusing training sessions", d, t); }, o.spot,
                                  o.train_quiet_sessions, o.train_heights);
  if (!o.out.empty()) {  // with the operating point it was measured at
    auto saved = model;
    saved.set_operating_point({o.spot.min_confidence, o.spot.confirm});
    saved.save(o.out);
  }
  const auto test = held_out_sessions(o.test_sessions, o.seed, [&](int d, int t) { progress("simulating and fusing test sessions", d, t); },
                                      o.test_noise_scale, o.test_height);
  const auto spotted = spot_sessions(model, test, o.spot);
  const auto quiet_runs = quiet_sessions(o.quiet_scenarios, o.quiet_sessions, o.seed,
                                         [&](int d, int t) { progress("simulating and fusing sessions without gestures", d, t); },
                                         o.test_noise_scale);
  const auto quiet = spot_quiet(model, quiet_runs, o.spot);
  // Recall against false events per hour, the operating point chosen at spotting time.
  std::vector<double> confidences{0.0, 0.25, 0.5, 0.75, 0.9}, confirms{0.0, 0.5};
  if (std::find(confidences.begin(), confidences.end(), o.spot.min_confidence) == confidences.end()) confidences.push_back(o.spot.min_confidence);
  if (std::find(confirms.begin(), confirms.end(), o.spot.confirm) == confirms.end()) confirms.push_back(o.spot.confirm);
  const auto curve = operating_curve(model, test, quiet_runs, o.spot, confidences, confirms, c.threads);
  nlohmann::json curve_json = nlohmann::json::array();
  for (const auto& p : curve) {
    curve_json.push_back({{"min_confidence", p.min_confidence}, {"confirm_s", p.confirm}, {"recall", p.recall},
                          {"precision", p.precision}, {"false_per_hour", p.false_per_hour},
                          {"median_latency_from_hold_s", p.median_latency_hold_s}});
  }
  nlohmann::json quiet_json{{"hours", quiet.hours}, {"events", quiet.events}, {"per_hour", nlohmann::json::object()},
                            {"scenarios", nlohmann::json::array()}};
  for (const auto& [label, n] : quiet.events) quiet_json["per_hour"][label] = quiet.per_hour(label);
  quiet_json["per_hour"]["point"] = quiet.per_hour("point");
  for (const auto& s : quiet.scenarios) {
    nlohmann::json false_events = nlohmann::json::array();
    for (const auto& e : s.spotted) false_events.push_back(event_json(e));
    quiet_json["scenarios"].push_back({{"scenario", s.name}, {"seconds", s.seconds}, {"events", s.events}, {"spotted", false_events}});
  }
  std::vector<SpottedEvent> events;
  std::vector<SpottingReport> reports;
  nlohmann::json per = nlohmann::json::array();
  for (std::size_t n = 0; n < test.size(); ++n) {
    const auto& s = test[n];
    const auto& ev = spotted[n].events;
    const auto& r = spotted[n].report;
    std::map<std::string, int> people;
    for (const auto& f : s.fused) ++people[std::to_string(f.person_id)];
    nlohmann::json tj = nlohmann::json::array();
    for (const auto& g : s.truth) {
      nlohmann::json e{{"label", g.label}, {"start_s", static_cast<double>(g.start_ns) * 1e-9}, {"end_s", static_cast<double>(g.end_ns) * 1e-9}};
      if (g.hold_ns >= 0) e["hold_s"] = static_cast<double>(g.hold_ns) * 1e-9;
      if (g.has_target) e["target"] = {g.target.x(), g.target.y(), g.target.z()};
      if (g.has_ray) {
        e["ray_origin"] = {g.ray_origin.x(), g.ray_origin.y(), g.ray_origin.z()};
        e["ray_direction"] = {g.ray_direction.x(), g.ray_direction.y(), g.ray_direction.z()};
      }
      tj.push_back(e);
    }
    nlohmann::json evj = nlohmann::json::array();
    for (const auto& e : ev) evj.push_back(event_json(e));
    per.push_back({{"truth_points", r.truth}, {"events", r.events}, {"f1", r.f1}, {"fused_frames_per_person", people},
                   {"truth", tj}, {"spotted", evj}});
    events.insert(events.end(), ev.begin(), ev.end());
    reports.push_back(r);
  }
  const auto r = combine(reports);  // each session scored against its own truth (their clocks overlap)
  auto whole = whole_hold_target_errors(test, model.pointing_correction());
  std::sort(whole.begin(), whole.end());
  const auto within = [](const std::vector<double>& v) { return std::count_if(v.begin(), v.end(), [](double e) { return e <= 0.15; }); };
  const nlohmann::json whole_json{{"holds", whole.size()},
                                  {"median_target_error_m", stats::median(whole)},
                                  {"max_target_error_m", whole.empty() ? 0.0 : whole.back()},
                                  {"within_15_cm", within(whole)}};
  if (o.json) {
    nlohmann::json ev = nlohmann::json::array();
    for (const auto& e : events) ev.push_back(event_json(e));
    std::printf("%s\n", nlohmann::json{{"train_sessions", o.train_sessions},
                                        {"test_sessions", o.test_sessions},
                                        {"seed", o.seed},
                                        {"test_noise_scale", o.test_noise_scale},
                                        {"test_height_m", o.test_height},
                                        {"train_heights_m", o.train_heights},
                                        {"clips", clips},
                                        {"config", config_json(c)},
                                        {"model", o.out},
                                        {"pointing_correction_deg", {{"elevation", model.pointing_correction().elevation},
                                                                     {"azimuth_out", model.pointing_correction().azimuth_out}}},
                                        {"pointing_joint_offsets_m",
                                         {{"shoulder", {model.pointing_correction().shoulder.x(), model.pointing_correction().shoulder.y(),
                                                        model.pointing_correction().shoulder.z()}},
                                          {"hand", {model.pointing_correction().hand.x(), model.pointing_correction().hand.y(),
                                                    model.pointing_correction().hand.z()}}}},
                                        {"spotting", to_json(r)},
                                        {"false_alarms", quiet_json},
                                        {"operating_point", {{"min_confidence", o.spot.min_confidence},
                                                             {"confirm_s", o.spot.confirm},
                                                             {"recall", r.recall},
                                                             {"false_per_hour", quiet.per_hour("point")}}},
                                        {"operating_curve", curve_json},
                                        {"spotted_within_15_cm", within(r.target_error_m)},
                                        {"whole_hold_reference", whole_json},
                                        {"sessions", per},
                                        {"events", ev}}
                            .dump(2)
                            .c_str());
    return 0;
  }
  std::printf("trained on %zu clips of %d simulated sessions%s; spotted on %d others:\n", clips, o.train_sessions,
              o.out.empty() ? "" : (" (model: " + o.out + ")").c_str(), o.test_sessions);
  std::printf("pointing: %d true, %d events: precision %.3f recall %.3f F1 %.3f; %.1f false events per hour between the gestures\n",
              r.truth, r.events, r.precision, r.recall, r.f1, r.false_per_hour);
  const auto& pc = model.pointing_correction();
  std::printf("pointing correction learnt on the training sessions: shoulder off by (%.1f, %.1f, %.1f) cm and hand by "
              "(%.1f, %.1f, %.1f) cm (out, up, forward); then rays lowered %.1f deg, turned in %.1f deg\n",
              100 * pc.shoulder.x(), 100 * pc.shoulder.y(), 100 * pc.shoulder.z(), 100 * pc.hand.x(), 100 * pc.hand.y(),
              100 * pc.hand.z(), pc.elevation, pc.azimuth_out);
  std::printf("latency: median %.0f ms after the hold began, %.0f ms from the end of the gesture (negative: before)\n",
              1e3 * r.median_latency_hold_s, 1e3 * r.median_latency_s);
  std::string by;
  for (const auto& s : quiet.scenarios) {
    const auto it = s.events.find("point");
    by += (by.empty() ? "" : ", ") + s.name + " " + std::to_string(it == s.events.end() ? 0 : it->second);
  }
  std::printf("false pointing events while nobody points: %.1f per hour (%d in %.0f s of %s)\n", quiet.per_hour("point"),
              quiet.events.count("point") ? quiet.events.at("point") : 0, quiet.hours * 3600.0, by.c_str());
  std::printf("operating points (--min-confidence, --confirm): recall / false pointing events per hour:");
  for (const auto& p : curve) std::printf("%s %.2f, %.2f s: %.3f / %.1f", &p == &curve.front() ? "" : ";", p.min_confidence, p.confirm, p.recall, p.false_per_hour);
  std::printf("\n");
  if (!r.target_error_m.empty())
    std::printf("target on the floor: median error %.1f cm, largest %.1f cm, %td of %zu within 15 cm; ray direction: median %.1f deg off\n",
                100 * r.median_target_error_m, 100 * r.max_target_error_m, within(r.target_error_m), r.target_error_m.size(),
                r.median_ray_error_deg);
  if (!whole.empty())
    std::printf("reference, the fused joints averaged over each whole true hold: median error %.1f cm, largest %.1f cm, %td of %zu "
                "within 15 cm\n",
                100 * stats::median(whole), 100 * whole.back(), within(whole), whole.size());
  return 0;
}

}  // namespace skelgraph::cli::gesture_cmd
