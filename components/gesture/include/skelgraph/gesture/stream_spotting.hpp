#pragma once
// Gestures in continuous annotated recordings (MSRC-12: each instance tagged
// at one action point): a classifier over a sliding window of the last
// `window_s`, trained on windows that end around the action points (the
// gesture's class) and windows that end away from every one (garbage);
// spotting fires an event when a gesture class wins `confirm` windows in a
// row, then stays quiet on that class for `refractory_s`. Scored against the
// action points (an event within `slack_s` of one matches it; latency =
// event - action point), per class and as a macro F1, leave-subject-out.
// Windows end at the newest frame, so the same runs live. No DDS.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/playback/readers.hpp"

namespace skelgraph::gesture {

struct AnnotatedStream {
  std::string source, subject;
  std::vector<std::int64_t> stamps;  // per frame
  Sequence x;                        // features per frame
  std::vector<playback::Annotation> annotations;
};

// A recording with annotations (playback::annotations_of: an
// .annotations.csv beside it, MSRC-12's .tagstream, per-frame labels) as a
// stream of features; a ModelError when it has none (unless `require` is
// false: spotting without scoring) or the feature set needs wrists it lacks. Ranges are trained on and scored at their end (the gesture
// is complete there); action points are ranges of no length. Subject: the recording's "subject"
// metadata, else the file name.
AnnotatedStream annotated_stream(const playback::Recording& recording, const FeatureOptions& features, bool require = true);

struct StreamSpotOptions {
  double window_s = 1.0;                                    // what the classifier sees
  std::vector<double> positive_offsets_s{-0.1, 0.0, 0.1, 0.2};  // training windows end this far from an action point
  double negative_gap_s = 0.8;                              // garbage windows end at least this far from every one
  double negative_step_s = 0.3;                             // ... one every this long
  // Garbage windows also end this far from each action point (a range's
  // end), unless another is within 0.3 s: a window of most of the gesture,
  // ending too early or too late, is not the gesture yet. Without them the
  // spotter fired up to 0.9 s before the action point (MSRC-12: macro F1
  // 0.653 without, docs/experiments/2026-12-06-msrc12-near-misses.md).
  std::vector<double> near_negative_offsets_s{-0.7, -0.5, 0.5, 0.7};
  double step_s = 0.1;                                      // spotting: a window every this long
  int confirm = 2;                                          // the same gesture class wins this many windows in a row
  double refractory_s = 1.5;                                // then no event of that class for this long
  double slack_s = 0.5;                                     // scoring: an event this close to an action point matches it
  // The window classifier: "knn" (each window resampled to `knn_samples`
  // frames and standardised; the majority of its `knn_k` nearest training
  // windows; as the windows come, no mirroring) or "hmm" (the Classifier,
  // one HMM per class). knn measured best on MSRC-12 (macro F1 0.65 against
  // 0.14-0.33).
  std::string model = "knn";
  int knn_k = 5, knn_samples = 10;
  nlohmann::json to_json() const;
};

// k nearest neighbours over resampled, standardised windows (StreamSpotOptions::model "knn").
class WindowKnn {
 public:
  WindowKnn(const std::vector<Clip>& clips, const ClassMap& map, int k, int samples);
  Decision classify(const Sequence& x) const;
  int garbage_index() const { return garbage_; }
  const std::vector<std::string>& labels() const { return labels_; }
  nlohmann::json to_json() const;
  static WindowKnn from_json(const nlohmann::json& j);  // throws ModelError naming the field

 private:
  WindowKnn() = default;
  Eigen::VectorXd vec(const Sequence& x) const;
  std::vector<std::string> labels_;
  int garbage_ = -1, k_ = 5, samples_ = 10;
  Eigen::VectorXd mean_, scale_;
  Eigen::MatrixXd train_;  // one standardised window per column
  std::vector<int> label_;
};

// `near_negative_offsets_s` from text: seconds, comma-separated, each in
// [-5, 5], or "none" (empty). std::invalid_argument names the bad item.
std::vector<double> parse_near_misses(const std::string& text);

// The classes of the streams' annotations (sorted), with "none" as garbage.
ClassMap stream_class_map(const std::vector<AnnotatedStream>& streams);
// Training windows of one stream (Clip.subject = the stream's).
std::vector<Clip> stream_windows(const AnnotatedStream& s, const ClassMap& map, const StreamSpotOptions& o);
// Events over a whole stream, as they would go out live.
std::vector<SpottedEvent> spot_stream(const Classifier& c, const AnnotatedStream& s, const StreamSpotOptions& o);
std::vector<SpottedEvent> spot_stream(const WindowKnn& c, const AnnotatedStream& s, const StreamSpotOptions& o);
// The stream's action points as truth to score events against.
std::vector<TruthGesture> stream_truth(const AnnotatedStream& s);

struct StreamSpotting {
  std::vector<std::string> classes;         // the gestures (garbage left out)
  std::vector<SpottingReport> per_class;    // pooled over every held-out stream
  double macro_f1 = 0.0;                    // mean of the classes' F1
  double median_latency_s = 0.0;            // over every matched event: event - action point
  std::size_t streams = 0, windows = 0;
  std::vector<std::string> subjects;
  nlohmann::json to_json() const;
};

// A trained stream spotter: the window classifier, its feature set and the
// spotting options, saved as JSON ("skelgraph-stream-spotter" version 1) by
// `gesture train --spot` and used by `gesture spot --model`.
class StreamSpotter {
 public:
  static StreamSpotter train(const std::vector<AnnotatedStream>& streams, const ClassifierOptions& c, const StreamSpotOptions& o);
  std::vector<SpottedEvent> spot(const AnnotatedStream& s) const;
  const std::vector<std::string>& classes() const;  // the gestures (garbage left out)
  FeatureSet feature_set() const { return features_; }
  const StreamSpotOptions& options() const { return options_; }
  std::size_t windows() const { return windows_; }
  void save(const std::string& path) const;
  static StreamSpotter load(const std::string& path);  // throws ModelError naming the file and field
  static bool is_stream_spotter(const std::string& path);  // the file says it is one

 private:
  FeatureSet features_ = FeatureSet::Body;
  StreamSpotOptions options_;
  std::vector<std::string> classes_;
  std::optional<WindowKnn> knn_;
  std::optional<Classifier> hmm_;
  std::size_t windows_ = 0;
};

// Leave-subject-out: for each subject, a classifier trained on the others'
// windows spots in that subject's streams.
StreamSpotting cross_validate_streams(const std::vector<AnnotatedStream>& streams, const ClassifierOptions& c,
                                      const StreamSpotOptions& o,
                                      const std::function<void(int done, int total)>& progress = {});

}  // namespace skelgraph::gesture
