// skelgraph gesture train|spot|classify|features on recorded clips, and the
// input handling every gesture subcommand shares.

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

#include "cmd_gesture.hpp"

namespace skelgraph::cli::gesture_cmd {

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

ClassifierOptions chosen_classifier_options(const GestureOptions& o) {
  auto c = classifier_options(o);
  if (!o.best_configuration) return c;
  DatasetOptions d;
  d.format = *playback::format_from_name(o.format);
  d.read = read_options(o);
  const auto best = best_configuration(o.classes, inputs_have_wrists(o.inputs, d));
  best.apply(c);
  std::fprintf(stderr, "model: %s, the best measured for these classes (%s); any model option (--features, --states, ...) leaves "
               "the choice to you%s\n", best.describe().c_str(), best.measured.c_str(),
               needs_wrists(best.features) ? "; it needs wrists, which the live gesture component does not have: for a live "
                                             "model give --features thesis8" : "");
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

int gesture_train(const GestureOptions& o) {
  if (o.spot_streams) return gesture_train_streams(o);
  const auto map = class_map(o.classes);
  const auto c = chosen_classifier_options(o);
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

}  // namespace skelgraph::cli::gesture_cmd
