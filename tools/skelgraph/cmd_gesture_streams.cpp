// skelgraph gesture train|cv|spot --spot: spotters for annotated continuous
// streams (MSRC-12, ...): trained, cross-validated leave-subject-out, run on files.

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
  SpotterOptions spot = o.spot;  // the model's operating point unless given
  if (!o.operating_point_given[0]) spot.min_confidence = model.operating_point().min_confidence;
  if (!o.operating_point_given[1]) spot.confirm = model.operating_point().confirm_s;
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
      auto& sp = spotters.try_emplace({s.sensor_id, s.person_id}, model, spot).first->second;
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
    std::printf("%s\n", nlohmann::json{{"model", o.model},
                                        {"operating_point", {{"min_confidence", spot.min_confidence}, {"confirm_s", spot.confirm}}},
                                        {"seconds", seconds},
                                        {"events_per_hour", per_hour},
                                        {"files", files}}
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

}  // namespace skelgraph::cli::gesture_cmd
