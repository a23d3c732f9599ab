#include "skelgraph/gesture/sim_sessions.hpp"

#include <algorithm>
#include <map>
#include <optional>

#include "classifier_internal.hpp"
#include "skelgraph/eval/offline.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::gesture {

using Eigen::Vector3d;
using skeleton::JointId;

SimSession simulate_session(std::uint64_t seed, const Surface& floor, double noise_scale, const std::string& scenario,
                            double height_m) {
  sim::SimConfig cfg;
  cfg.scenario.name = scenario;
  cfg.scenario.seed = seed;
  cfg.scenario.height = height_m;
  cfg.noise_scale = noise_scale;
  sim::Simulation simulation(cfg);
  std::map<std::string, Eigen::Isometry3d> poses;
  for (const auto& s : cfg.sensors) poses[s.id] = s.world_from_sensor();
  std::vector<eval::TimedSkeleton> events;
  struct TruthFrame {
    std::int64_t t;
    std::string phase;
    skeleton::Skeleton s;
  };
  std::vector<TruthFrame> truth;
  for (auto& e : simulation.advance(simulation.duration() + 1.0)) {
    const auto t = cfg.epoch_ns + static_cast<std::int64_t>(std::llround(e.t * 1e9));
    if (e.kind == sim::SimEvent::Kind::Truth) {
      std::string phase;
      for (const auto& a : simulation.scenario().at(e.t).actors)
        if (a.person_id == e.actor) phase = a.phase;
      truth.push_back({t, phase, e.skeleton});
      events.push_back({eval::TimedSkeleton::Kind::Truth, t, std::move(e.skeleton)});
    } else if (e.kind == sim::SimEvent::Kind::Raw) {
      events.push_back({eval::TimedSkeleton::Kind::Raw, t, std::move(e.skeleton)});
    }
  }
  std::stable_sort(events.begin(), events.end(), [](const auto& a, const auto& b) { return a.t_ns < b.t_ns; });
  SimSession out;
  out.scenario = scenario;
  eval::OfflineOptions eo;
  eo.methods = {fusion::Method::Kalman};
  eo.singles = false;
  eval::evaluate(poses, events, eo, [&](fusion::Method, const skeleton::Skeleton& s) { out.fused.push_back(s); });

  if (scenario != "point") return out;  // nobody gestures
  // Runs of non-rest phases are gestures.
  for (std::size_t i = 0; i < truth.size();) {
    if (truth[i].phase == "rest") {
      std::size_t j = i;
      while (j < truth.size() && truth[j].phase == "rest") ++j;
      out.rest.emplace_back(truth[i].t, truth[j - 1].t);
      i = j;
      continue;
    }
    std::size_t j = i;
    while (j < truth.size() && truth[j].phase != "rest") ++j;
    TruthGesture g;
    g.start_ns = truth[i].t;
    g.end_ns = truth[j - 1].t;
    g.label = truth[i].phase.substr(0, truth[i].phase.find(':'));
    Vector3d target = Vector3d::Zero(), origin = Vector3d::Zero(), dir = Vector3d::Zero();
    int hits = 0, holds = 0;
    for (std::size_t k = i; k < j; ++k) {
      const auto& p = truth[k].phase;
      if (p.rfind("hold:", 0) != 0) continue;
      g.label = "point";
      if (g.hold_ns < 0) g.hold_ns = truth[k].t;
      const bool right = p == "hold:right";
      const auto& s = truth[k].s;
      const Vector3d sh = s[right ? JointId::RightShoulder : JointId::LeftShoulder].position;
      const Vector3d ha = s[right ? JointId::RightHand : JointId::LeftHand].position;
      origin += sh;
      dir += (ha - sh).normalized();
      ++holds;
      if (const auto hit = intersect(sh, (ha - sh).normalized(), floor)) {
        target += *hit;
        ++hits;
      }
    }
    if (g.label == "raise") g.label = "point";
    if (holds > 0) {
      g.has_ray = true;
      g.ray_origin = origin / holds;
      g.ray_direction = dir.normalized();
    }
    if (hits > 0) {
      g.has_target = true;
      g.target = target / hits;
    }
    out.truth.push_back(g);
    i = j;
  }
  // The hold frames with the fused skeleton of the same moment (the fused
  // person nearest the truth: a tracker's brief ghost twin is another id).
  std::size_t f = 0;
  for (const auto& tf : truth) {
    if (tf.phase.rfind("hold:", 0) != 0) continue;
    while (f < out.fused.size() && out.fused[f].stamp_ns < tf.t - 20'000'000) ++f;
    const skeleton::Skeleton* best = nullptr;
    double best_d = 0.3;
    for (std::size_t k = f; k < out.fused.size() && out.fused[k].stamp_ns <= tf.t + 20'000'000; ++k) {
      const double d = (out.fused[k][JointId::Torso].position - tf.s[JointId::Torso].position).norm();
      if (d < best_d) best_d = d, best = &out.fused[k];
    }
    if (best) out.holds.push_back({*best, tf.s, tf.phase == "hold:right"});
  }
  return out;
}

namespace {

// A hold frame's pointing arm, when the fused skeleton tracks both shoulders and that arm's hand.
struct HoldArm {
  JointId shoulder, hand;
  ArmFrame frame;
};
std::optional<HoldArm> hold_arm(const SimSession::Hold& h) {
  const JointId sh = h.right ? JointId::RightShoulder : JointId::LeftShoulder;
  const JointId ha = h.right ? JointId::RightHand : JointId::LeftHand;
  const auto& l = h.fused[JointId::LeftShoulder];
  const auto& r = h.fused[JointId::RightShoulder];
  if (l.confidence < skeleton::kTracked || r.confidence < skeleton::kTracked || h.fused[sh].confidence < skeleton::kTracked ||
      h.fused[ha].confidence < skeleton::kTracked)
    return std::nullopt;
  return HoldArm{sh, ha, ArmFrame(r.position - l.position, h.right)};
}

}  // namespace

void learn_joint_offsets(const std::vector<SimSession>& sessions, PointingCorrection& c) {
  std::vector<double> d[2][3];  // [shoulder, hand][out, up, forward]
  for (const auto& s : sessions)
    for (const auto& h : s.holds) {
      const auto arm = hold_arm(h);
      if (!arm) continue;
      const Vector3d a = arm->frame.to_body(h.fused[arm->shoulder].position - h.truth[arm->shoulder].position);
      const Vector3d b = arm->frame.to_body(h.fused[arm->hand].position - h.truth[arm->hand].position);
      for (int k = 0; k < 3; ++k) d[0][k].push_back(a[k]), d[1][k].push_back(b[k]);
    }
  if (d[0][0].empty()) return;
  for (int k = 0; k < 3; ++k) {
    c.shoulder[k] = stats::median(d[0][k]);
    c.hand[k] = stats::median(d[1][k]);
  }
}

std::vector<double> whole_hold_target_errors(const std::vector<SimSession>& sessions, const PointingCorrection& c,
                                             const Surface& floor) {
  std::vector<double> out;
  for (const auto& s : sessions)
    for (const auto& g : s.truth) {
      if (g.label != "point" || !g.has_target) continue;
      Vector3d sh = Vector3d::Zero(), ha = Vector3d::Zero(), o = Vector3d::Zero();
      int n = 0;
      for (const auto& h : s.holds) {
        if (h.truth.stamp_ns < g.start_ns || h.truth.stamp_ns > g.end_ns) continue;
        const auto arm = hold_arm(h);
        if (!arm) continue;
        sh += h.fused[arm->shoulder].position - arm->frame.to_world(c.shoulder);
        ha += h.fused[arm->hand].position - arm->frame.to_world(c.hand);
        o += arm->frame.out;
        ++n;
      }
      if (n == 0) continue;
      const Vector3d origin = sh / n;
      if (const auto hit = intersect(origin, corrected((ha - sh).normalized(), o.normalized(), c), floor))
        out.push_back((*hit - g.target).norm());
    }
  return out;
}

ClassMap sim_class_map() {
  ClassMap m;
  m.classes = {"point", "other"};
  m.action_class = {{"point", "point"}};
  m.garbage = "other";
  return m;
}

namespace {
// The session's fused frames from..to as a clip of `action` (none: fewer than 5 frames).
void cut_clip(const SimSession& s, std::int64_t from, std::int64_t to, const std::string& action, const std::string& subject,
              const ClassMap& map, FeatureSet set, std::vector<Clip>& clips) {
  std::vector<skeleton::Skeleton> frames;
  for (const auto& f : s.fused)
    if (f.stamp_ns >= from && f.stamp_ns <= to) frames.push_back(f);
  if (frames.size() < 5) return;
  Clip c;
  c.action = action;
  c.subject = subject;
  c.source = c.subject + ":" + action + "@" + std::to_string(from);
  c.label = map.label_of(action).value_or(-1);
  c.x = features_of(frames, FeatureOptions{set, skeleton::kTracked}).x;
  clips.push_back(std::move(c));
}
}  // namespace

std::vector<Clip> session_clips(const std::vector<SimSession>& sessions, const ClassMap& map, FeatureSet set, double pad) {
  std::vector<Clip> clips;
  const auto pad_ns = static_cast<std::int64_t>(pad * 1e9);
  for (std::size_t n = 0; n < sessions.size(); ++n) {
    const auto& s = sessions[n];
    const auto cut = [&](std::int64_t from, std::int64_t to, const std::string& action) {
      cut_clip(s, from, to, action, "sim" + std::to_string(n), map, set, clips);
    };
    for (const auto& g : s.truth) cut(g.start_ns - pad_ns, g.end_ns + pad_ns, g.label);
    for (const auto& [a, b] : s.rest)
      if (b - a > 1'000'000'000) cut(a + (b - a) / 2 - 500'000'000, a + (b - a) / 2 + 500'000'000, "rest");
  }
  return clips;
}

}  // namespace skelgraph::gesture

namespace skelgraph::gesture {

std::vector<SimSession> held_out_sessions(int sessions, std::uint64_t seed, const std::function<void(int, int)>& progress,
                                          double noise_scale, double height_m) {
  std::vector<SimSession> out;
  for (int i = 0; i < sessions; ++i) {
    out.push_back(simulate_session((seed + 1) * 1000 + 500 + static_cast<std::uint64_t>(i), {}, noise_scale, "point", height_m));
    if (progress) progress(i + 1, sessions);
  }
  return out;
}

SpotterOptions sim_spotter_options() {
  SpotterOptions o;
  o.max_target = 4.0;
  o.max_lean_m = 0.07;
  return o;
}

const std::vector<std::string>& quiet_scenarios() {
  static const std::vector<std::string> names{"walk", "360", "hide", "box", "occ", "sit", "arms", "work"};
  return names;
}

std::vector<SimSession> quiet_sessions(const std::vector<std::string>& scenarios, int per_scenario, std::uint64_t seed,
                                       const std::function<void(int, int)>& progress, double noise_scale, bool training) {
  std::vector<SimSession> out;
  const int total = per_scenario * static_cast<int>(scenarios.size());
  const std::uint64_t first = training ? seed * 1000 + 300 : (seed + 1) * 1000 + 700;
  for (const auto& name : scenarios) {
    for (int i = 0; i < per_scenario; ++i) {
      out.push_back(simulate_session(first + static_cast<std::uint64_t>(i), {}, noise_scale, name));
      if (progress) progress(static_cast<int>(out.size()), total);
    }
  }
  return out;
}

double QuietReport::per_hour(const std::string& label) const {
  const auto it = events.find(label);
  return hours > 0 ? (it == events.end() ? 0 : it->second) / hours : 0.0;
}

QuietReport spot_quiet(const Classifier& model, const std::vector<SimSession>& sessions, const SpotterOptions& options) {
  QuietReport r;
  const auto spotted = spot_sessions(model, sessions, options);
  for (std::size_t n = 0; n < sessions.size(); ++n) {
    const auto& s = sessions[n];
    auto it = std::find_if(r.scenarios.begin(), r.scenarios.end(), [&](const auto& x) { return x.name == s.scenario; });
    if (it == r.scenarios.end()) it = r.scenarios.insert(r.scenarios.end(), QuietReport::Scenario{s.scenario, 0, {}, {}});
    if (!s.fused.empty()) {
      const double seconds = static_cast<double>(s.fused.back().stamp_ns - s.fused.front().stamp_ns) * 1e-9;
      it->seconds += seconds;
      r.hours += seconds / 3600.0;
    }
    for (const auto& e : spotted[n].events) {
      ++it->events[e.label];
      ++r.events[e.label];
      it->spotted.push_back(e);
    }
  }
  return r;
}

std::vector<OperatingPoint> operating_curve(const Classifier& model, const std::vector<SimSession>& test,
                                            const std::vector<SimSession>& quiet, const SpotterOptions& options,
                                            const std::vector<double>& min_confidences, const std::vector<double>& confirms,
                                            int threads) {
  std::vector<OperatingPoint> out;
  for (const double confirm : confirms) {
    for (const double min_confidence : min_confidences) out.push_back({min_confidence, confirm});
  }
  detail::parallel_for(static_cast<int>(out.size()), threads, [&](int i) {
    auto& p = out[static_cast<std::size_t>(i)];
    SpotterOptions o = options;
    o.confirm = p.confirm;
    o.min_confidence = p.min_confidence;
    std::vector<SpottingReport> reports;
    for (const auto& s : spot_sessions(model, test, o)) reports.push_back(s.report);
    const auto r = combine(reports);
    p.recall = r.recall;
    p.precision = r.precision;
    p.median_latency_hold_s = r.median_latency_hold_s;
    p.false_per_hour = spot_quiet(model, quiet, o).per_hour(o.point_label);
  });
  return out;
}

std::vector<SessionSpotting> spot_sessions(const Classifier& model, const std::vector<SimSession>& sessions,
                                           const SpotterOptions& options) {
  std::vector<SessionSpotting> out;
  for (const auto& s : sessions) {
    SessionSpotting r;
    std::map<std::uint32_t, Spotter> spotters;  // one per fused person
    for (const auto& f : s.fused)
      for (const auto& e : spotters.try_emplace(f.person_id, model, options).first->second.step(f)) r.events.push_back(e);
    r.report = score_spotting(r.events, s.truth, "point");
    if (!s.fused.empty()) {  // the session outside its pointing gestures
      double inside = 0;
      for (const auto& g : s.truth)
        if (g.label == "point") inside += 1e-9 * static_cast<double>(g.end_ns - g.start_ns);
      r.report.non_gesture_s = 1e-9 * static_cast<double>(s.fused.back().stamp_ns - s.fused.front().stamp_ns) - inside;
      finish(r.report);
    }
    out.push_back(std::move(r));
  }
  return out;
}

ClassifierOptions sim_classifier_options() {
  ClassifierOptions c;
  c.features.set = FeatureSet::Thesis8;
  c.hands = Hands::Canonical;
  c.trimmed = false;
  return c;
}

Classifier train_on_sim(int sessions, std::uint64_t seed, const ClassifierOptions& options, std::size_t* clips,
                        const std::function<void(int, int)>& progress, const SpotterOptions& spot_options, int quiet_per_scenario,
                        const std::vector<double>& heights_m) {
  if (heights_m.empty()) throw ModelError("train_on_sim: no training heights");
  // Training sees every event, however unsure or short: the operating point is the user's, at spotting time.
  SpotterOptions spot = spot_options;
  spot.min_confidence = 0.0;
  spot.confirm = 0.0;
  spot.min_straightness = 0.0;
  spot.max_lean_m = 0.0;
  std::vector<SimSession> train;
  for (int i = 0; i < sessions; ++i) {
    train.push_back(simulate_session(seed * 1000 + static_cast<std::uint64_t>(i), {}, 1.0, "point",
                                     heights_m[static_cast<std::size_t>(i) % heights_m.size()]));
    if (progress) progress(i + 1, sessions);
  }
  const auto map = sim_class_map();
  auto c = session_clips(train, map, options.features.set);
  auto model = Classifier::train(c, map, options);
  // The pointing correction: first the joints' offsets, then the median
  // angles by which the rays spotted from the corrected joints still miss the true ones.
  PointingCorrection pc;
  learn_joint_offsets(train, pc);
  model.set_pointing_correction(pc);
  // Hard negatives: what this model takes for pointing in training sessions
  // where nobody gestures (work, carrying, sitting...), cut as the spotter
  // cut it, joins the garbage class; then trained again.
  if (quiet_per_scenario > 0) {
    const auto quiet = quiet_sessions(quiet_scenarios(), quiet_per_scenario, seed, {}, 1.0, true);
    const auto spotted = spot_sessions(model, quiet, spot);
    const auto pad_ns = static_cast<std::int64_t>(spot.pad * 1e9);
    for (std::size_t n = 0; n < quiet.size(); ++n) {
      for (const auto& e : spotted[n].events) {
        cut_clip(quiet[n], e.start_ns - pad_ns, e.end_ns, "work", "quiet" + std::to_string(n), map, options.features.set, c);
      }
    }
    model = Classifier::train(c, map, options);
    model.set_pointing_correction(pc);
  }
  if (clips) *clips = c.size();
  std::vector<double> el, az;
  const auto spotted = spot_sessions(model, train, spot);
  for (std::size_t n = 0; n < train.size(); ++n)
    for (const auto& e : spotted[n].events) {
      if (!e.has_ray) continue;
      for (const auto& g : train[n].truth)
        if (g.label == "point" && g.has_ray && e.end_ns >= g.start_ns - 500'000'000 && e.end_ns <= g.end_ns + 500'000'000) {
          const auto off = ray_offset(e.ray_direction, g.ray_direction, e.out);
          el.push_back(off.elevation);
          az.push_back(off.azimuth_out);
          break;
        }
    }
  if (!el.empty()) {
    pc.elevation = stats::median(el);
    pc.azimuth_out = stats::median(az);
    model.set_pointing_correction(pc);
  }
  return model;
}

}  // namespace skelgraph::gesture
