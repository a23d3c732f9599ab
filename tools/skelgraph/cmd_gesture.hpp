#pragma once
// `skelgraph gesture`: what its subcommands (cmd_gesture*.cpp) share: the
// options, the entry points, and reading the inputs the way every
// subcommand does (class sets, clips, annotated streams, classifier options).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/dataset.hpp"
#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/gesture/stream_spotting.hpp"

namespace skelgraph::cli::gesture_cmd {

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
  bool best_configuration = false;  // train, cv on clips: no model option given, so the class set's best measured
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
  bool operating_point_given[2] = {false, false};  // --min-confidence, --confirm given (else a clip model's own)
  double gap = 0.0;
  double rest = 0.0;
};

// Entry points, one per subcommand (and their --spot / --model variants).
int gesture_train(const GestureOptions& o);
int gesture_train_streams(const GestureOptions& o);
int gesture_cv(const GestureOptions& o);
int gesture_cv_streams(const GestureOptions& o);
int gesture_spot(const GestureOptions& o);
int gesture_spot_model(const GestureOptions& o);
int gesture_classify(const GestureOptions& o);
int gesture_features(const GestureOptions& o);
int gesture_sim(const GestureOptions& o);

// classifier_options, with the class set's best measured configuration
// (gesture::best_configuration) when `best_configuration` is set; says which on stderr.
ClassifierOptions chosen_classifier_options(const GestureOptions& o);

// Shared by them (cmd_gesture_clips.cpp, cmd_gesture_cv.cpp, cmd_gesture_streams.cpp).
ClassMap class_map(const std::string& c);
ClassifierOptions classifier_options(const GestureOptions& o);
playback::ReadOptions read_options(const GestureOptions& o);
// The clips of the inputs; a bad file is reported in `bad` and left out.
std::vector<Clip> load(const GestureOptions& o, const ClassMap& map, const ClassifierOptions& c, BadInputs& bad);
std::string pct(double v);
nlohmann::json config_json(const ClassifierOptions& c);
CvOptions cv_options(const GestureOptions& o);

}  // namespace skelgraph::cli::gesture_cmd
