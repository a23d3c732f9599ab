// skelgraph gesture train|cv|classify: HMM gesture classifiers on recorded data sets.

#include <cmath>
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

namespace skelgraph::cli {

namespace {

using namespace skelgraph::gesture;

struct GestureOptions {
  std::vector<std::string> inputs;
  std::string format = "kinder-gator";
  std::string classes = "two-class";
  std::string features = "thesis8";
  int states = 7, mixtures = 1, garbage_mixtures = 0;
  std::string covariance = "full";
  std::string hands = "canonical";
  bool no_trim = false;
  bool per_class = false;
  bool prefixes = false;
  bool nearest = false;  // cv: the DTW nearest-neighbour experiment instead of the HMMs
  double reject_quantile = 0.02;
  int iterations = 100;
  double tolerance = 1e-4;
  std::string init = "segments";
  int restarts = 1;
  std::uint64_t seed = 1;
  int threads = 2;
  bool json = false;
  std::string on_error = "stop";  // a bad line in an input: stop (the file is bad) or skip it
  // train / classify
  std::string out, model;
  // cv
  std::string split = "lso";
  int folds = 5;
  std::string svg;
  std::vector<int> sweep_states, sweep_mixtures;
  std::vector<std::string> sweep_covariance, sweep_init;
  bool sweep = false;
  bool nested = false;
  bool spot_streams = false;  // cv --spot: annotated continuous streams (MSRC-12), leave-subject-out spotting
  StreamSpotOptions stream;
  // sim
  int train_sessions = kTrainSessions, test_sessions = 4;
  double test_noise_scale = 1.0;  // gesture sim: the test sessions' tracker noise
  double test_height = 1.75;      // gesture sim: the test sessions' people's height
  std::vector<double> train_heights{1.75};  // gesture sim: the training sessions' people's heights, in turn
  std::vector<std::string> quiet_scenarios = gesture::quiet_scenarios();  // gesture sim: where nobody gestures
  int quiet_sessions = 1;                                                  // ... sessions of each
  int train_quiet_sessions = kTrainQuietSessions;                          // ... to train against (hard negatives)
  SpotterOptions spot;
  double gap = 0.0;
  double rest = 0.0;
};

ClassMap class_map(const std::string& c) {
  const auto& presets = ClassMap::preset_names();
  if (std::find(presets.begin(), presets.end(), c) != presets.end()) return ClassMap::preset(c);
  if (!std::filesystem::exists(c)) throw UsageError("--classes: '" + c + "' is neither a preset (two-class, five-class, robot) nor a file");
  return ClassMap::load(c);
}

ClassifierOptions classifier_options(const GestureOptions& o) {
  ClassifierOptions c;
  c.hmm.states = o.states;
  c.hmm.mixtures = o.mixtures;
  c.hmm.covariance = o.covariance == "diag" ? Covariance::Diagonal : Covariance::Full;
  c.hmm.max_iterations = o.iterations;
  c.hmm.tolerance = o.tolerance;
  c.hmm.init = o.init == "kmeans" ? Init::KMeans : Init::Segments;
  c.hmm.restarts = o.restarts;
  c.nearest = o.nearest;
  c.hmm.seed = o.seed;
  c.garbage_mixtures = o.garbage_mixtures;
  c.features.set = *feature_set_from_name(o.features);
  c.hands = *hands_from_name(o.hands);
  c.per_action = !o.per_class;
  c.prefixes = o.prefixes;
  c.trimmed = !o.no_trim;
  c.reject_quantile = o.reject_quantile;
  c.threads = o.threads;
  return c;
}

playback::ReadOptions read_options(const GestureOptions& o) {
  playback::ReadOptions r;
  r.on_error = o.on_error == "skip" ? playback::ReadOptions::OnError::Skip : playback::ReadOptions::OnError::Stop;
  return r;
}

// The clips of the inputs; a bad file is reported in `bad` and left out.
std::vector<Clip> load(const GestureOptions& o, const ClassMap& map, const ClassifierOptions& c, BadInputs& bad) {
  DatasetOptions d;
  d.format = *playback::format_from_name(o.format);
  d.features = c.features;
  d.trim = c.trimmed;
  d.read = read_options(o);
  LoadReport report;
  auto clips = load_clips(o.inputs, map, d, &report);
  for (const auto& p : report.skipped) std::fprintf(stderr, "note: %s\n", p.c_str());
  for (const auto& p : report.bad) bad.add(p);
  std::vector<int> per(map.classes.size(), 0);
  int unlabelled = 0;
  for (const auto& clip : clips) clip.label >= 0 ? ++per[static_cast<std::size_t>(clip.label)] : ++unlabelled;
  std::string counts;
  for (std::size_t k = 0; k < per.size(); ++k) counts += (k ? ", " : "") + map.classes[k] + " " + std::to_string(per[k]);
  std::fprintf(stderr, "read %zu clips (%s; %d in no class)\n", clips.size(), counts.c_str(), unlabelled);
  for (std::size_t k = 0; k < per.size(); ++k)
    if (per[k] == 0) throw UsageError("no clip of class '" + map.classes[k] + "' in the inputs (check --classes and the actions)");
  return clips;
}

std::string pct(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f %%", 100 * v);
  return b;
}

const char* init_name(Init i) { return i == Init::KMeans ? "kmeans" : "segments"; }

nlohmann::json config_json(const ClassifierOptions& c) {
  return {{"features", feature_set_name(c.features.set)},
          {"states", c.hmm.states},
          {"mixtures", c.hmm.mixtures},
          {"garbage_mixtures", c.garbage_mixtures > 0 ? c.garbage_mixtures : c.hmm.mixtures},
          {"covariance", c.hmm.covariance == Covariance::Full ? "full" : "diag"},
          {"init", init_name(c.hmm.init)},
          {"restarts", c.hmm.restarts},
          {"hands", hands_name(c.hands)},
          {"per_action", c.per_action},
          {"prefixes", c.prefixes},
          {"trimmed", c.trimmed}};
}

int gesture_train_streams(const GestureOptions& o);
int gesture_spot_model(const GestureOptions& o);

int gesture_train(const GestureOptions& o) {
  if (o.spot_streams) return gesture_train_streams(o);
  const auto map = class_map(o.classes);
  const auto c = classifier_options(o);
  BadInputs bad;
  const auto clips = load(o, map, c, bad);
  std::fprintf(stderr, "training %zu models ...\n", map.classes.size());
  const auto model = Classifier::train(clips, map, c);
  if (!o.out.empty()) model.save(o.out);
  if (o.json) {
    nlohmann::json j{{"clips", clips.size()}, {"labels", model.labels()}, {"threshold", model.threshold()},
                     {"config", config_json(c)}, {"classes", map.to_json()}, {"out", o.out}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("trained %zu models (%zu classes) on %zu clips; rejection threshold %.3f log-likelihood per frame%s\n", model.models().size(), map.classes.size(),
                clips.size(), model.threshold(), o.out.empty() ? " (not saved: no --out)" : ("; saved to " + o.out).c_str());
  }
  return bad.exit_code(0, expand_paths(o.inputs).size());
}

struct CvRun {
  ClassifierOptions config;
  Metrics metrics;
  std::vector<ClipResult> results;
};

CvOptions cv_options(const GestureOptions& o) {
  CvOptions cv;
  cv.split = o.split == "kfold" ? Split::KFold : o.split == "size" ? Split::BodySize : Split::LeaveSubjectOut;
  cv.folds = o.folds;
  cv.seed = o.seed;
  return cv;
}

CvRun run_cv(const GestureOptions& o, const ClassMap& map, const std::vector<Clip>& clips, const ClassifierOptions& c,
             const std::string& what) {
  Progress progress;
  const auto results = cross_validate(clips, map, c, cv_options(o), [&](int done, int total) {
    progress(what + ": fold " + std::to_string(done) + "/" + std::to_string(total), done == total);
  });
  return {c, evaluate(results, map.classes), results};
}

// The inputs as annotated streams (annotations required unless `require` is
// false); a bad file is reported in `bad` and left out.
std::vector<AnnotatedStream> load_streams(const GestureOptions& o, const FeatureOptions& features, bool require, BadInputs& bad) {
  const auto format = *playback::format_from_name(o.format);
  std::vector<AnnotatedStream> streams;
  for (const auto& file : expand_paths(o.inputs)) {
    bad.guard([&] {
      const auto rec = playback::read_recording(format, file, read_options(o));
      note_skipped(rec);
      try {
        streams.push_back(annotated_stream(rec, features, require));
      } catch (const ModelError& e) {
        throw UsageError(e.what());
      }
    });
  }
  std::size_t tags = 0;
  for (const auto& s : streams) tags += s.annotations.size();
  std::fprintf(stderr, "read %zu streams (%zu annotations)\n", streams.size(), tags);
  if (streams.empty()) throw UsageError(require ? "no annotated stream among the inputs" : "no stream among the inputs");
  return streams;
}

ClassifierOptions stream_classifier_options(const GestureOptions& o) {
  auto c = classifier_options(o);
  c.trimmed = false;  // windows are classified whole
  return c;
}

// train --spot: a stream spotter from every annotated stream, saved for `gesture spot --model`.
int gesture_train_streams(const GestureOptions& o) {
  const auto c = stream_classifier_options(o);
  BadInputs bad;
  const auto streams = load_streams(o, c.features, true, bad);
  const auto spotter = StreamSpotter::train(streams, c, o.stream);
  if (!o.out.empty()) spotter.save(o.out);
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"streams", streams.size()},
                                       {"classes", spotter.classes()},
                                       {"training_windows", spotter.windows()},
                                       {"config", config_json(c)},
                                       {"spotting", o.stream.to_json()},
                                       {"out", o.out}}
                            .dump(2)
                            .c_str());
  } else {
    std::printf("stream spotter (%s windows, %s features) trained on %zu windows of %zu streams, %zu classes%s\n",
                o.stream.model.c_str(), feature_set_name(c.features.set), spotter.windows(), streams.size(),
                spotter.classes().size(), o.out.empty() ? " (not saved: no --out)" : ("; saved to " + o.out).c_str());
  }
  return bad.exit_code(0, expand_paths(o.inputs).size());
}

// spot --model: a saved stream spotter over recordings; scored where they have annotations.
// spot --model with a clip classifier (`gesture train`, `gesture sim --out`,
// the built-in `sim`): the live component's spotter over each recording's
// people, its events listed and counted per hour (false alarms, where nobody
// makes the model's gestures).
int gesture_spot_classifier(const GestureOptions& o) {
  const auto model = is_builtin_model(o.model) ? load_builtin_model(o.model) : Classifier::load(o.model);
  const auto format = *playback::format_from_name(o.format);
  BadInputs bad;
  nlohmann::json files = nlohmann::json::array();
  std::map<std::string, std::size_t> by_label;
  double seconds = 0;
  const auto paths = expand_paths(o.inputs);
  for (const auto& file : paths) {
    playback::Recording rec;
    if (!bad.guard([&] { rec = playback::read_recording(format, file, read_options(o)); })) continue;
    note_skipped(rec);
    const auto wrists = wrists_of(rec);
    if (needs_wrists(model.feature_set()) && wrists.empty())
      throw UsageError(file + ": the model's '" + feature_set_name(model.feature_set()) + "' features need wrists; this recording has none");
    std::map<std::pair<std::string, std::uint32_t>, Spotter> spotters;
    nlohmann::json ev = nlohmann::json::array();
    const auto t0 = rec.frames.front().stamp_ns;
    for (std::size_t i = 0; i < rec.frames.size(); ++i) {
      const auto& s = rec.frames[i];
      auto& sp = spotters.try_emplace({s.sensor_id, s.person_id}, model, o.spot).first->second;
      for (const auto& e : sp.step(s, wrists.empty() ? nullptr : &wrists[i])) {
        ev.push_back({{"label", e.label}, {"person_id", e.person_id}, {"time_s", 1e-9 * static_cast<double>(e.end_ns - t0)},
                      {"confidence", e.confidence}});
        ++by_label[e.label];
      }
    }
    const double span = 1e-9 * static_cast<double>(rec.frames.back().stamp_ns - t0);
    seconds += span;
    if (!o.json) std::printf("%s: %zu events in %.1f s\n", file.c_str(), ev.size(), span);
    files.push_back({{"file", file}, {"span_s", span}, {"events", ev}});
  }
  nlohmann::json per_hour = nlohmann::json::object();
  for (const auto& [label, n] : by_label) per_hour[label] = seconds > 0 ? static_cast<double>(n) * 3600.0 / seconds : 0.0;
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"model", o.model}, {"seconds", seconds}, {"events_per_hour", per_hour}, {"files", files}}
                             .dump(2)
                             .c_str());
  } else {
    std::printf("%.1f min of recordings:", seconds / 60.0);
    if (by_label.empty()) std::printf(" no events");
    for (const auto& [label, n] : by_label) std::printf(" %s %zu (%.1f per hour)", label.c_str(), n, per_hour[label].get<double>());
    std::printf("\n");
  }
  return bad.exit_code(0, paths.size());
}

int gesture_spot_model(const GestureOptions& o) {
  if (!StreamSpotter::is_stream_spotter(o.model)) return gesture_spot_classifier(o);
  const auto spotter = StreamSpotter::load(o.model);
  FeatureOptions f;
  f.set = spotter.feature_set();
  BadInputs bad;
  const auto streams = load_streams(o, f, false, bad);
  std::map<std::string, std::vector<SpottingReport>> reports;
  nlohmann::json files = nlohmann::json::array();
  std::size_t annotated = 0;
  for (const auto& s : streams) {
    const auto events = spotter.spot(s);
    nlohmann::json ev = nlohmann::json::array();
    const auto t0 = s.stamps.empty() ? 0 : s.stamps.front();
    for (const auto& e : events)
      ev.push_back({{"label", e.label}, {"time_s", 1e-9 * static_cast<double>(e.end_ns - t0)}, {"confidence", e.confidence}});
    files.push_back({{"file", s.source}, {"events", ev}, {"annotations", s.annotations.size()}});
    if (!o.json) {
      std::printf("%s: %zu events", s.source.c_str(), events.size());
      for (const auto& e : events) std::printf("%s %s at %.2f s", &e == &events.front() ? ":" : ",", e.label.c_str(),
                                               1e-9 * static_cast<double>(e.end_ns - t0));
      std::printf("\n");
    }
    if (s.annotations.empty()) continue;
    ++annotated;
    const auto truth = stream_truth(s);
    for (const auto& k : spotter.classes()) reports[k].push_back(score_spotting(events, truth, k, spotter.options().slack_s));
  }
  nlohmann::json out{{"model", o.model}, {"files", files}};
  if (annotated > 0) {
    nlohmann::json per = nlohmann::json::array();
    double macro = 0;
    std::vector<double> latencies;
    for (const auto& k : spotter.classes()) {
      const auto r = combine(reports[k]);
      per.push_back(to_json(r));
      macro += r.f1 / static_cast<double>(spotter.classes().size());
      latencies.insert(latencies.end(), r.latency_s.begin(), r.latency_s.end());
      if (!o.json)
        std::printf("  %-28s %3d annotated, %3d events: precision %.3f recall %.3f F1 %.3f; latency median %+.0f ms\n",
                    ("'" + k + "'").c_str(), r.truth, r.events, r.precision, r.recall, r.f1, 1e3 * r.median_latency_s);
    }
    out["per_class"] = per;
    out["macro_f1"] = macro;
    out["median_latency_s"] = stats::median(latencies);
    if (!o.json) std::printf("macro F1 %.3f over %zu annotated streams; events a median %+.0f ms after the annotation\n", macro,
                             annotated, 1e3 * stats::median(latencies));
  }
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
  return bad.exit_code(0, expand_paths(o.inputs).size());
}

// cv --spot: annotated streams, leave-subject-out, a sliding-window spotter (stream_spotting.hpp).
int gesture_cv_streams(const GestureOptions& o) {
  const auto c = stream_classifier_options(o);
  BadInputs bad;
  const auto streams = load_streams(o, c.features, true, bad);
  const auto files = expand_paths(o.inputs);
  Progress progress;
  StreamSpotting r;
  try {
    r = cross_validate_streams(streams, c, o.stream, [&](int done, int total) {
      progress("held-out subject " + std::to_string(done) + "/" + std::to_string(total), done == total);
    });
  } catch (const ModelError& e) {
    throw UsageError(std::string("gesture cv --spot: ") + e.what());
  }
  if (o.json) {
    auto j = r.to_json();
    j["config"] = config_json(c);
    j["spotting"] = o.stream.to_json();
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("leave-subject-out spotting in %zu annotated streams of %zu subjects (a %.1f s window every %.1f s, %d in a "
                "row; an event within %.1f s of an action point matches it):\n",
                r.streams, r.subjects.size(), o.stream.window_s, o.stream.step_s, o.stream.confirm, o.stream.slack_s);
    for (const auto& k : r.per_class)
      std::printf("  %-28s %3d tagged, %3d events: precision %.3f recall %.3f F1 %.3f; latency median %+.0f ms\n",
                  ("'" + k.label + "'").c_str(), k.truth, k.events, k.precision, k.recall, k.f1, 1e3 * k.median_latency_s);
    std::printf("macro F1 %.3f; events a median %+.0f ms after the action point\n", r.macro_f1, 1e3 * r.median_latency_s);
  }
  return bad.exit_code(0, files.size());
}

int gesture_cv(const GestureOptions& o) {
  if (o.spot_streams) return gesture_cv_streams(o);
  const auto map = class_map(o.classes);
  const auto base = classifier_options(o);
  BadInputs bad;
  const auto clips = load(o, map, base, bad);
  std::vector<ClassifierOptions> configs;
  if (o.sweep) {
    const std::vector<int> states = o.sweep_states.empty() ? std::vector<int>{3, 5, 7, 9} : o.sweep_states;
    const std::vector<int> mixtures = o.sweep_mixtures.empty() ? std::vector<int>{1, 2, 3} : o.sweep_mixtures;
    const std::vector<std::string> covs = o.sweep_covariance.empty() ? std::vector<std::string>{"full", "diag"} : o.sweep_covariance;
    const std::vector<std::string> inits = o.sweep_init.empty() ? std::vector<std::string>{o.init} : o.sweep_init;
    for (const auto& init : inits)
      for (const auto& cov : covs)
        for (int s : states)
          for (int m : mixtures) {
            auto c = base;
            c.hmm.states = s;
            c.hmm.mixtures = m;
            c.hmm.covariance = cov == "diag" ? Covariance::Diagonal : Covariance::Full;
            c.hmm.init = init == "kmeans" ? Init::KMeans : Init::Segments;
            configs.push_back(c);
          }
  } else {
    configs.push_back(base);
  }
  const auto config_name = [](const ClassifierOptions& c) {
    return std::to_string(c.hmm.states) + " states, " + std::to_string(c.hmm.mixtures) + " mixtures, " +
           (c.hmm.covariance == Covariance::Full ? "full" : "diag") + ", " + init_name(c.hmm.init) + " init";
  };
  std::vector<CvRun> runs;
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const auto& c = configs[i];
    const std::string what = "config " + std::to_string(i + 1) + "/" + std::to_string(configs.size()) + " (" + config_name(c) + ")";
    runs.push_back(run_cv(o, map, clips, c, what));
  }
  // The winner: accuracy, then the first class's F1, then detection AUC.
  std::size_t best = 0;
  for (std::size_t i = 1; i < runs.size(); ++i)
    if (better(runs[i].metrics, runs[best].metrics)) best = i;
  // --nested: the same choice made inside each fold, scored on the held-out fold.
  std::optional<NestedCv> nested;
  Metrics nested_metrics;
  if (o.nested) {
    Progress progress;
    nested = nested_cross_validate(clips, map, configs, cv_options(o), [&](int done, int total) {
      progress("nested: outer fold " + std::to_string(done) + "/" + std::to_string(total), done == total);
    });
    nested_metrics = evaluate(nested->results, map.classes);
  }
  const auto& win = runs[best];
  const std::string split = o.split == "kfold" ? std::to_string(o.folds) + "-fold stratified"
                            : o.split == "size" ? "by body size (shorter arms vs longer, both ways)"
                                                : "leave-subject-out";
  if (!o.svg.empty()) {
    std::ofstream f(o.svg);
    f << confusion_svg(win.metrics, split + ", " + o.classes);
    if (!f) throw std::runtime_error("cannot write " + o.svg);
  }
  if (o.json) {
    nlohmann::json j{{"split", o.split == "kfold" ? "kfold" : o.split == "size" ? "size" : "leave-subject-out"},
                     {"folds", o.split == "kfold" ? o.folds : -1},
                     {"clips", clips.size()},
                     {"classes", map.to_json()},
                     {"config", config_json(win.config)},
                     {"metrics", to_json(win.metrics)}};
    if (o.split == "size") {  // what the halves were cut by
      std::map<std::string, std::vector<double>> arms;
      for (const auto& c : clips)
        if (std::isfinite(c.arm_length_m)) arms[c.subject].push_back(c.arm_length_m);
      auto& by = j["arm_length_m_by_subject"] = nlohmann::json::object();
      for (const auto& [subject, v] : arms) by[subject] = stats::median(v);
    }
    auto& per = j["clips"] = nlohmann::json::array();
    for (const auto& r : win.results) {
      const auto& clip = clips[r.clip];
      nlohmann::json scores = nlohmann::json::object();
      for (std::size_t k = 0; k < map.classes.size(); ++k) scores[map.classes[k]] = r.decision.scores[k];
      per.push_back({{"file", clip.source},
                     {"subject", clip.subject},
                     {"action", clip.action},
                     {"truth", r.truth >= 0 ? nlohmann::json(map.classes[static_cast<std::size_t>(r.truth)]) : nlohmann::json(nullptr)},
                     {"predicted", map.classes[static_cast<std::size_t>(r.decision.label)]},
                     {"rejected", r.decision.rejected},
                     {"fold", r.fold},
                     {"scores", scores}});
    }
    if (nested) {
      auto& n = j["nested"] = nlohmann::json::object();
      n["metrics"] = to_json(nested_metrics);
      auto& chosen = n["chosen"] = nlohmann::json::array();
      for (int c : nested->chosen) chosen.push_back(config_json(configs[static_cast<std::size_t>(c)]));
    }
    if (o.sweep) {
      auto& s = j["sweep"] = nlohmann::json::array();
      for (const auto& r : runs) {
        auto e = config_json(r.config);
        e["accuracy"] = r.metrics.accuracy;
        e["f1_" + map.classes[0]] = r.metrics.f1[0];
        // the last tie-breaker of the choice (null where there is no detection ROC)
        e["detection_auc"] = std::isfinite(r.metrics.detection_auc) ? nlohmann::json(r.metrics.detection_auc) : nlohmann::json();
        s.push_back(e);
      }
    }
    std::printf("%s\n", j.dump(2).c_str());
    return bad.exit_code(0, expand_paths(o.inputs).size());
  }
  if (o.sweep) {
    std::printf("%-6s %-7s %-9s %-9s %-9s %s\n", "states", "mixt.", "cov.", "init", "accuracy", ("F1 " + map.classes[0]).c_str());
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const auto& r = runs[i];
      std::printf("%-6d %-7d %-9s %-9s %-9s %.3f%s\n", r.config.hmm.states, r.config.hmm.mixtures,
                  r.config.hmm.covariance == Covariance::Full ? "full" : "diag", init_name(r.config.hmm.init),
                  pct(r.metrics.accuracy).c_str(), r.metrics.f1[0],
                  i == best ? "  <- best" : "");
    }
    std::printf("\nbest configuration:\n");
  }
  const auto& m = win.metrics;
  std::printf("%s, %zu clips, features %s, %d states, %d mixtures, %s covariance, %s initialisation%s\n", split.c_str(),
              clips.size(), feature_set_name(win.config.features.set), win.config.hmm.states, win.config.hmm.mixtures,
              win.config.hmm.covariance == Covariance::Full ? "full" : "diagonal", init_name(win.config.hmm.init),
              win.config.hmm.restarts > 1 ? (", best of " + std::to_string(win.config.hmm.restarts) + " restarts").c_str() : "");
  std::printf("%s", confusion_text(m).c_str());
  std::printf("accuracy %s", pct(m.accuracy).c_str());
  std::printf("; %s precision %.3f recall %.3f F1 %.3f", m.labels[0].c_str(), m.precision[0], m.recall[0], m.f1[0]);
  if (std::isfinite(m.detection_auc)) std::printf("; detection AUC %.3f", m.detection_auc);
  std::printf("\nwith rejection: accuracy %s (%d labelled clips rejected", pct(m.accuracy_with_rejection).c_str(), m.rejected_labelled);
  if (m.unlabelled) std::printf("; %d of %d clips in no class rejected; rejection AUC %.3f", m.unlabelled_rejected, m.unlabelled, m.rejection_auc);
  std::printf(")\n");
  if (nested) {
    const auto& n = nested_metrics;
    std::printf("\nnested cross-validation (the configuration chosen inside each fold, on its training subjects only):\n");
    std::map<std::string, int> count;
    for (int c : nested->chosen) ++count[config_name(configs[static_cast<std::size_t>(c)])];
    for (const auto& [name, k] : count) std::printf("  %s: chosen in %d of %zu folds\n", name.c_str(), k, nested->chosen.size());
    std::printf("%s", confusion_text(n).c_str());
    std::printf("accuracy %s; %s precision %.3f recall %.3f F1 %.3f\n", pct(n.accuracy).c_str(), n.labels[0].c_str(), n.precision[0],
                n.recall[0], n.f1[0]);
  }
  if (!o.svg.empty()) std::printf("confusion matrix written to %s\n", o.svg.c_str());
  return bad.exit_code(0, expand_paths(o.inputs).size());
}

// Leave-subject-out spotting in continuous streams of real clips (gesture/clip_spotting.hpp).
int gesture_spot(const GestureOptions& o) {
  if (!o.model.empty()) return gesture_spot_model(o);
  const auto map = class_map(o.classes);
  const auto c = classifier_options(o);
  BadInputs bad;
  const auto clips = load(o, map, c, bad);
  ClipStreamOptions so;
  so.format = *playback::format_from_name(o.format);
  so.read = read_options(o);
  so.gap_s = o.gap;
  so.rest_s = o.rest;
  so.spot = o.spot;
  Progress progress;
  ClipSpotting r;
  try {
    r = spot_clips(clips, map, c, so, [&](int done, int total) {
      progress("spotted subject " + std::to_string(done) + "/" + std::to_string(total), done == total);
    });
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("gesture spot: ") + e.what());
  }
  if (o.json) {
    nlohmann::json per = nlohmann::json::array();
    for (const auto& s : r.subjects) {
      per.push_back({{"subject", s.subject}, {"clips", s.clips}, {"truth", s.report.truth}, {"events", s.report.events},
                     {"true_positive", s.report.true_positive}, {"f1", s.report.f1}, {"spotted", s.spotted},
                     {"clips_in_stream", s.clips_in_stream}});
    }
    std::printf("%s\n", nlohmann::json{{"label", r.label}, {"config", config_json(c)}, {"gap_s", o.gap}, {"rest_s", o.rest},
                                        {"spotting", to_json(r.combined)}, {"subjects", per}}
                            .dump(2)
                            .c_str());
    return bad.exit_code(0, expand_paths(o.inputs).size());
  }
  const auto& t = r.combined;
  std::printf("leave-subject-out spotting in continuous streams of %zu clips (%.1f s of the last frame held, %.1f s of arms-down rest "
              "between them):\n", clips.size(), o.gap, o.rest);
  std::printf("%s: %d true, %d events: precision %.3f recall %.3f F1 %.3f; %.1f false events per hour of the streams outside "
              "its clips (%.2f h); latency from the end of the motion: median %.0f ms\n",
              r.label.c_str(), t.truth, t.events, t.precision, t.recall, t.f1, t.false_per_hour, t.non_gesture_s / 3600.0,
              1e3 * t.median_latency_s);
  return bad.exit_code(0, expand_paths(o.inputs).size());
}

int gesture_classify(const GestureOptions& o) {
  const auto model = Classifier::load(o.model);
  DatasetOptions d;
  d.format = *playback::format_from_name(o.format);
  d.features.set = model.feature_set();
  d.trim = model.trimmed();
  d.read = read_options(o);
  nlohmann::json all = nlohmann::json::array();
  BadInputs bad;
  const auto files = expand_paths(o.inputs);
  for (const auto& file : files) {
    Sequence x;
    if (!bad.guard([&] {
          const auto rec = playback::read_recording(d.format, file, d.read);
          note_skipped(rec);
          if (rec.frames.size() < 2)
            throw playback::DataError(file, rec.report.last_line, "one skeleton frame only: a clip needs at least 2");
          x = clip_features(rec, d);
        })) {
      if (o.json) all.push_back({{"file", file}, {"error", bad.messages().back()}});
      continue;
    }
    const auto dec = model.classify(x);
    const std::string label = dec.rejected ? "none" : model.labels()[static_cast<std::size_t>(dec.label)];
    if (o.json) {
      nlohmann::json s = nlohmann::json::object();
      for (std::size_t k = 0; k < dec.scores.size(); ++k) s[model.labels()[k]] = dec.scores[k];
      all.push_back({{"file", file},
                     {"label", label},
                     {"best", model.labels()[static_cast<std::size_t>(dec.label)]},
                     {"rejected", dec.rejected},
                     {"margin", dec.margin},
                     {"scores", s}});
    } else {
      std::printf("%s: %s (margin %.2f%s)\n", file.c_str(), label.c_str(), dec.margin,
                  dec.rejected ? (", best " + model.labels()[static_cast<std::size_t>(dec.label)] + " below the threshold").c_str() : "");
    }
  }
  if (o.json) std::printf("%s\n", all.dump(2).c_str());
  return bad.exit_code(0, files.size());
}

int gesture_features(const GestureOptions& o) {
  FeatureOptions f;
  f.set = *feature_set_from_name(o.features);
  const auto format = *playback::format_from_name(o.format);
  const auto names = feature_names(f.set);
  std::printf("file,frame,stamp_s,complete");
  for (const auto& n : names) std::printf(",%s", n.c_str());
  std::printf("\n");
  BadInputs bad;
  const auto files = expand_paths(o.inputs);
  for (const auto& file : files) {
    playback::Recording rec;
    if (!bad.guard([&] { rec = playback::read_recording(format, file, read_options(o)); })) continue;
    note_skipped(rec);
    const auto ft = recording_features(rec, f);
    for (Eigen::Index t = 0; t < ft.x.rows(); ++t) {
      const auto& s = rec.frames[static_cast<std::size_t>(t)];
      std::printf("%s,%td,%.4f,%d", file.c_str(), t, static_cast<double>(s.stamp_ns) * 1e-9,
                  ft.complete[static_cast<std::size_t>(t)] ? 1 : 0);
      for (Eigen::Index i = 0; i < ft.x.cols(); ++i) std::printf(",%.6g", ft.x(t, i));
      std::printf("\n");
    }
  }
  return bad.exit_code(0, files.size());
}

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
  }
  if (e.has_target) {
    j["target"] = {e.target.x(), e.target.y(), e.target.z()};
    j["target_name"] = e.target_name;
  }
  return j;
}

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
  if (!o.out.empty()) model.save(o.out);
  const auto test = held_out_sessions(o.test_sessions, o.seed, [&](int d, int t) { progress("simulating and fusing test sessions", d, t); },
                                      o.test_noise_scale, o.test_height);
  const auto spotted = spot_sessions(model, test, o.spot);
  const auto quiet = spot_quiet(model,
                                quiet_sessions(o.quiet_scenarios, o.quiet_sessions, o.seed,
                                               [&](int d, int t) { progress("simulating and fusing sessions without gestures", d, t); },
                                               o.test_noise_scale),
                                o.spot);
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

void add_model_options(CLI::App* c, GestureOptions& o);

// --spot and the stream spotter's options (cv, train).
void add_stream_options(CLI::App* c, GestureOptions& o, const std::string& what) {
  c->add_flag("--spot", o.spot_streams, what);
  c->add_option("--window-model", o.stream.model, "--spot: the window classifier, knn (default) or hmm (the --states ... options)")
      ->check(CLI::IsMember({"hmm", "knn"}));
  c->add_option("--knn-k", o.stream.knn_k, "--spot --window-model knn: neighbours (default 5)")->check(CLI::Range(1, 100));
  c->add_option("--window", o.stream.window_s, "--spot: s the classifier looks back (default 1.0)")->check(CLI::Range(0.2, 10.0));
  c->add_option("--step", o.stream.step_s, "--spot: s between windows (default 0.1)")->check(CLI::Range(0.01, 2.0));
  c->add_option("--confirm", o.stream.confirm, "--spot: windows in a row one gesture must win (default 2)")->check(CLI::Range(1, 50));
  c->add_option("--refractory", o.stream.refractory_s, "--spot: s without another event of the same class (default 1.5)")
      ->check(CLI::Range(0.0, 30.0));
}

void add_common(CLI::App* c, GestureOptions& o, bool model_options) {
  c->add_option("inputs", o.inputs, "recordings (files, or directories of .csv files)")->required()->check(CLI::ExistingPath);
  c->add_option("--format", o.format, "input format (default kinder-gator)")->check(CLI::IsMember(playback::format_names()));
  c->add_flag("--json", o.json, "machine-readable output");
  c->add_option("--on-error", o.on_error, "a bad line in an input: stop (default: the file is bad, reported, the others still "
                                          "read, exit 2 at the end) or skip the line")
      ->check(CLI::IsMember({"stop", "skip"}));
  if (!model_options) return;
  c->add_flag("--no-trim", o.no_trim, "keep each clip whole (default: only the part where the arms move)");
  c->add_option("--classes", o.classes, "two-class (point vs garbage; default), five-class, robot (point, stop, come_here, wave, other), or a class-mapping YAML file");
  add_model_options(c, o);
}

void add_model_options(CLI::App* c, GestureOptions& o) {
  c->add_option("--features", o.features, "feature set: thesis8 (default; the thesis's 8), extended, body, hands, arm (hands and arm need wrists: Kinect v1/v2 recordings)")
      ->check(CLI::IsMember({"body", "thesis8", "extended", "hands", "arm"}));
  c->add_option("--states", o.states, "HMM states (default 7)")->check(CLI::Range(1, 50));
  c->add_option("--mixtures", o.mixtures, "Gaussians per state (default 1)")->check(CLI::Range(1, 20));
  c->add_option("--garbage-mixtures", o.garbage_mixtures, "Gaussians per state of the garbage model (default: --mixtures)")
      ->check(CLI::Range(1, 20));
  c->add_option("--covariance", o.covariance, "full (default) or diag")->check(CLI::IsMember({"full", "diag"}));
  c->add_option("--hands", o.hands,
                "canonical (default): mirror every clip so its more active arm is the right; augment: also train on mirrored "
                "clips; as-is")
      ->check(CLI::IsMember({"canonical", "augment", "as-is"}));
  c->add_flag("--prefixes", o.prefixes, "also train on each clip's first 50 % and 70 % (for spotting, which decides early)");
  c->add_flag("--per-class", o.per_class, "one model per class (the thesis) instead of one per recorded action");
  c->add_option("--reject-quantile", o.reject_quantile, "share of held-out training clips the rejection threshold may reject (default 0.02; spotting with a garbage class leaves "
                "'no gesture' to it and ignores the threshold)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--iterations", o.iterations, "Baum-Welch iteration cap (default 100)")->check(CLI::Range(1, 10000));
  c->add_option("--init", o.init,
                "first parameters: segments (default: each clip cut into equal parts, a state per part) or kmeans (k-means++ over "
                "all frames, a state per cluster, uniform transitions)")
      ->check(CLI::IsMember({"segments", "kmeans"}));
  c->add_option("--restarts", o.restarts,
                "train each model this many times from different seeds and keep the one that fits its training clips best "
                "(default 1)")
      ->check(CLI::Range(1, 100));
  c->add_option("--tolerance", o.tolerance, "Baum-Welch stops when the log-likelihood per frame gains less (default 1e-4)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--seed", o.seed, "seed for initialisation and folds (default 1)");
  c->add_option("--threads", o.threads, "worker threads (default 2)")->check(CLI::Range(1, 64));
}

// The spotter's settings, the same on `gesture spot` and `gesture sim`.
// Returns --max-target, whose default differs between spot and sim.
CLI::Option* add_spotter_options(CLI::App* c, GestureOptions& o) {
  c->add_option("--hold", o.spot.hold, "s an extended arm is held before pointing is tried (default 0.25)")->check(CLI::Range(0.0, 5.0));
  c->add_option("--aim", o.spot.aim,
                "s of the hold the pointing ray is averaged over, at most: the event goes out when the arm moves again or then "
                "(default 1.5; at most --hold: at once, from a --hold look)")
      ->check(CLI::Range(0.0, 10.0));
  c->add_option("--still-speed", o.spot.still_speed, "m/s below which a hand is still (default 0.25)")->check(CLI::Range(0.01, 5.0));
  c->add_option("--min-raise", o.spot.min_raise,
                "degrees from hanging straight down an extended arm must be raised to count as a pointing hold (default 35)")
      ->check(CLI::Range(0.0, 180.0));
  auto* max_target = c->add_option("--max-target", o.spot.max_target,
                "m: pointing must land on a surface within this of the shoulder (0: any ray, none needed; default 4 in "
                "gesture sim, the simulated cell's floor; 0 in gesture spot: where a recording's surfaces are is not known)")
      ->check(CLI::Range(0.0, 100.0));
  c->add_option("--other-arm-free", o.spot.other_arm_free,
                "pointing needs the other arm not held out as well (default true)");
  c->add_option("--confirm", o.spot.confirm,
                "s pointing must stay held after --hold before the event goes out, or it is dropped (default 0: none)")
      ->check(CLI::Range(0.0, 10.0));
  c->add_option("--min-confidence", o.spot.min_confidence,
                "events less sure than this (1 - exp(-margin) over the next class) are dropped (default 0)")
      ->check(CLI::Range(0.0, 1.0));
  return max_target;
}

}  // namespace

void add_gesture_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* g = app.add_subcommand("gesture", "Gesture recognition with HMMs: train, cross-validate, classify recorded clips");
  g->require_subcommand(1);
  auto o = std::make_shared<GestureOptions>();

  auto* t = g->add_subcommand("train", "Train one HMM per class (and the rejection threshold) on labelled clips; with --spot a "
                                       "stream spotter on annotated continuous streams");
  add_common(t, *o, true);
  add_stream_options(t, *o,
                     "the inputs are annotated continuous streams (see cv --spot): train a sliding-window stream spotter "
                     "on all of them, for `gesture spot --model`; --features defaults to body here");
  t->add_option("--out", o->out, "write the classifier (JSON)");
  t->callback([o, t, &run] {
    if (o->spot_streams && t->get_option("--features")->count() == 0) o->features = "body";
    run = [o] { return gesture_train(*o); };
  });

  auto* cv = g->add_subcommand("cv", "Cross-validate: confusion matrix, accuracy, per-class precision/recall/F1, ROC");
  add_common(cv, *o, true);
  add_stream_options(cv, *o,
                     "the inputs are annotated continuous streams (an .annotations.csv beside each file, or --format msrc12's "
                     ".tagstream): leave one subject out, spot with a sliding window, score events against the annotations "
                     "(per class P/R/F1, macro F1, latency); --features defaults to body here");
  cv->add_flag("--nearest", o->nearest,
               "an experiment: each clip takes the class of its nearest training clip by dynamic time warping (the "
               "features and --hands as given; the HMM options unused); cross-validation only");
  cv->add_option("--split", o->split,
                 "lso: leave one subject out (default); kfold: stratified k-fold; size: the subjects with the shorter "
                 "arms against those with the longer (trained on one half, tested on the other, both ways)")
      ->check(CLI::IsMember({"lso", "kfold", "size"}));
  cv->add_option("--folds", o->folds, "k for --split kfold (default 5)")->check(CLI::Range(2, 1000));
  cv->add_option("--svg", o->svg, "write the confusion matrix as SVG");
  cv->add_flag("--sweep", o->sweep, "try every states x mixtures x covariance (x initialisation) combination and report the best");
  cv->add_flag("--nested", o->nested,
               "with --sweep: also choose the configuration inside each fold from its training clips alone and score it on the "
               "held-out fold (the unbiased figure for the sweep's winner; about folds x the sweep's time)")
      ->needs("--sweep");
  cv->add_option("--sweep-states", o->sweep_states, "states to try (default 3 5 7 9)")->check(CLI::Range(1, 50));
  cv->add_option("--sweep-mixtures", o->sweep_mixtures, "mixtures to try (default 1 2 3)")->check(CLI::Range(1, 20));
  cv->add_option("--sweep-covariance", o->sweep_covariance, "covariances to try (default full diag)")
      ->check(CLI::IsMember({"full", "diag"}));
  cv->add_option("--sweep-init", o->sweep_init, "initialisations to try (default: --init's)")
      ->check(CLI::IsMember({"segments", "kmeans"}));
  cv->callback([o, cv, &run] {
    // --spot's defaults are its best measured configuration (docs/experiments/2026-12-04-msrc12-spotting.md).
    if (o->spot_streams && cv->get_option("--features")->count() == 0) o->features = "body";
    run = [o] { return gesture_cv(*o); };
  });

  auto* f = g->add_subcommand("features", "Print the per-frame features of recordings as CSV (what the models see)");
  add_common(f, *o, false);
  f->add_option("--features", o->features, "feature set: thesis8 (default; the thesis's 8), extended, body, hands, arm (hands and arm need wrists: Kinect v1/v2 recordings)")
      ->check(CLI::IsMember({"body", "thesis8", "extended", "hands", "arm"}));
  f->callback([o, &run] { run = [o] { return gesture_features(*o); }; });

  auto* sp = g->add_subcommand("spot", "Spot gestures in continuous streams of recorded clips: each subject's clips one "
                                      "after another, a model trained on the other subjects; precision, recall, latency");
  add_common(sp, *o, true);
  sp->add_option("--rest", o->rest,
                 "s of rest put between clips (and before the first and after the last): the arms lowered over 0.5 s to hang "
                 "below the shoulders, held, raised over 0.5 s into the next clip (default 0: none)")
      ->check(CLI::Range(0.0, 10.0));
  sp->add_option("--gap", o->gap, "s of the last frame held between clips (default 0: the clips' own idle starts and ends are the rest)")->check(CLI::Range(0.0, 10.0));
  add_spotter_options(sp, *o);
  sp->add_option("--model", o->model,
                 "spot with a trained model in the inputs (no training): a stream spotter from `gesture train --spot` (scored "
                 "where the inputs have annotations), or a clip classifier (a file, or the built-in 'sim') run through the "
                 "live component's spotter (events listed and counted per hour)")
      ->check(CLI::ExistingFile | CLI::IsMember(builtin_model_names()));
  sp->callback([o, &run] { run = [o] { return gesture_spot(*o); }; });

  auto* sm = g->add_subcommand("sim", "Simulated pointing sessions (no outside data): train a classifier on some, spot "
                                     "gestures in the others' fused stream and score precision, recall, latency and target error");
  sm->add_flag("--json", o->json, "machine-readable output");
  add_model_options(sm, *o);
  sm->add_option("--train-sessions", o->train_sessions, "pointing sessions to train on (default 24)")->check(CLI::Range(1, 200));
  sm->add_option("--test-sessions", o->test_sessions, "sessions to spot on (default 4)")->check(CLI::Range(1, 200));
  sm->add_option("--train-heights", o->train_heights,
                 "the training sessions' people's heights, m, one session each in turn (default 1.75: the built-in model)")
      ->delimiter(',')
      ->check(CLI::Range(1.0, 2.2));
  sm->add_option("--test-height", o->test_height,
                 "the test sessions' people's height, m (training: 1.75): how the model does on people of another size")
      ->check(CLI::Range(1.0, 2.2));
  sm->add_option("--test-noise-scale", o->test_noise_scale,
                 "scale of the trackers' random errors in the test sessions (default 1; 0 leaves the skeleton convention's "
                 "offsets, the lag and the geometry: how far the targets are off without the tracker's noise)")
      ->check(CLI::Range(0.0, 10.0));
  sm->add_option("--quiet-scenarios", o->quiet_scenarios,
                 "simulator scenarios where nobody gestures, spotted for false alarms (default walk,360,hide,box,occ,sit,arms,work)")
      ->delimiter(',')
      ->check(CLI::IsMember(sim::scenario_names()));
  sm->add_option("--quiet-sessions", o->quiet_sessions, "sessions of each of them (default 1; 0: none)")->check(CLI::Range(0, 200));
  sm->add_option("--train-quiet-sessions", o->train_quiet_sessions,
                 "training sessions of each of them whose false alarms the model is trained again against (default 8; 0: none)")
      ->check(CLI::Range(0, 200));
  sm->add_option("--out", o->out, "write the trained classifier (JSON), e.g. for the gesture component");
  auto* sim_max_target = add_spotter_options(sm, *o);
  sm->add_option("--window", o->spot.window, "s over which hand speed is measured (default 0.25)")->check(CLI::Range(0.03, 2.0));
  sm->callback([o, sim_max_target, &run] {
    if (sim_max_target->count() == 0) o->spot.max_target = sim_spotter_options().max_target;  // the cell's floor
    run = [o] { return gesture_sim(*o); };
  });

  auto* c = g->add_subcommand("classify", "Classify recordings with a trained classifier");
  add_common(c, *o, false);
  c->add_option("--model", o->model, "classifier file from `gesture train`")->required()->check(CLI::ExistingFile);
  c->callback([o, &run] { run = [o] { return gesture_classify(*o); }; });
}

}  // namespace skelgraph::cli
