#pragma once
// Gesture classification with one HMM per class: highest likelihood wins,
// an optional garbage class (everything that is not a gesture of interest,
// as the thesis's two-class setup), and a rejection threshold below which the
// answer is "no gesture". Cross-validation (stratified k-fold and
// leave-subject-out), confusion matrices, per-class precision/recall/F1 and
// ROC curves. Eigen and std only: no DDS.

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/gesture/features.hpp"
#include "skelgraph/gesture/hmm.hpp"

namespace skelgraph::gesture {

// Which recorded actions make which class. File (YAML):
//   classes:            # in this order; each class lists the actions it takes
//     point: [Point-at-the-camera]
//   garbage: other      # optional: every unlisted action becomes this class
// Without `garbage`, unlisted actions take part in no training; cross-validation
// scores them as inputs that should be rejected.
struct ClassMap {
  std::vector<std::string> classes;                  // model order; the garbage class (if any) is last
  std::map<std::string, std::string> action_class;   // action -> class
  std::string garbage;                               // "" if none

  static ClassMap preset(const std::string& name);   // "two-class", "five-class"; throws ModelError
  static ClassMap load(const std::string& path);     // throws ModelError naming the file and field
  static const std::vector<std::string>& preset_names();
  // The class index of an action, or nullopt when it is not used.
  std::optional<int> label_of(const std::string& action) const;
  int garbage_index() const;  // -1 without a garbage class
  nlohmann::json to_json() const;
};

// A model file's JSON; ModelError naming the file when it cannot be read or is not JSON.
nlohmann::json read_model_json(const std::string& path);

// One labelled recording: its features and where it came from.
struct Clip {
  std::string source;   // file
  std::string subject;  // for leave-subject-out
  std::string action;   // as recorded
  int label = -1;       // class index, -1: not in any class (a rejection test input)
  Sequence x;
  double arm_length_m = std::numeric_limits<double>::quiet_NaN();  // shoulder-elbow-hand, median over the clip (the size split)
};

// Either hand may perform a gesture. Canonical: every clip (in training and
// when classifying) is mirrored so that its more active arm is the right one.
// Augment: train on every clip and its mirror image. AsIs: neither.
enum class Hands { Canonical, Augment, AsIs };
std::optional<Hands> hands_from_name(const std::string& name);  // "canonical", "augment", "as-is"
const char* hands_name(Hands h);

struct ClassifierOptions {
  TrainOptions hmm;                  // states, mixtures, covariance for every class model
  int garbage_mixtures = 0;          // mixtures of the garbage models; 0: the same as the others
  FeatureOptions features;
  Hands hands = Hands::Canonical;
  bool per_action = true;            // one model per recorded action; a class scores its best action model
  bool prefixes = false;             // also train on each clip's first 50 % and 70 % (live spotting decides early)
  bool trimmed = true;               // the clips are cut to their motion_span (recorded in the model: classify the same way)
  double reject_quantile = 0.02;     // the threshold accepts this share less than all held-out training clips
  int calibration_folds = 3;         // held-out scores for the threshold come from this many inner folds (0: training scores)
  int threads = 2;
  // Cross-validation only, an experiment beside the HMMs: each clip takes the
  // class of its nearest training clip by dynamic time warping (features
  // standardised over the training frames; Sakoe-Chiba band of `nearest_band`
  // of the longer clip). Classifier::train refuses it.
  bool nearest = false;
  double nearest_band = 0.2;
};

// Dynamic time warping: the Euclidean frame distances summed along the best
// alignment within a band of `band` x the longer length (at least their
// difference), divided by the two lengths' sum. +inf when either is empty.
double dtw_distance(const Sequence& a, const Sequence& b, double band);

struct Decision {
  int label = -1;                 // the best class
  bool rejected = false;          // its score is below the threshold: "no gesture"
  std::vector<double> scores;     // per class: log-likelihood per frame
  double margin = 0.0;            // best score minus the next best
};

// A constant correction of pointing rays, learnt against known targets
// (`gesture sim` against the simulator's truth): trackers place the hand and
// shoulder joints where they are not, so the shoulder -> hand ray is off by
// a repeatable angle. Degrees: the ray is lowered by `elevation` and turned
// inwards (towards the body's midline) by `azimuth_out`.
//
// Before that, the joints themselves: a tracker's shoulder and hand sit a
// constant offset from the true joints in the body's frame (its skeleton
// convention), and what that does to the ray depends on where the arm
// points, so no single angle undoes it. `shoulder` and `hand` are those
// offsets, metres, as (out, up, forward): out along the shoulders towards
// the pointing arm's side, up vertical, forward the way the torso faces.
struct PointingCorrection {
  double elevation = 0.0, azimuth_out = 0.0;
  Eigen::Vector3d shoulder = Eigen::Vector3d::Zero(), hand = Eigen::Vector3d::Zero();
};

class Classifier {
 public:
  // Trains the models of every class on the clips with a label (>= 0): one per
  // class, or one per action a class takes (per_action).
  static Classifier train(const std::vector<Clip>& clips, const ClassMap& map, const ClassifierOptions& options);

  Decision classify(const Sequence& x) const;
  const std::vector<std::string>& labels() const { return labels_; }
  int garbage_index() const { return garbage_; }
  double threshold() const { return threshold_; }
  void set_threshold(double t) { threshold_ = t; }
  const std::vector<Hmm>& models() const { return models_; }
  const std::vector<int>& model_classes() const { return model_class_; }  // the class of each model
  FeatureSet feature_set() const { return features_; }
  Hands hands() const { return hands_; }
  bool trimmed() const { return trimmed_; }
  const PointingCorrection& pointing_correction() const { return pointing_; }
  void set_pointing_correction(const PointingCorrection& p) { pointing_ = p; }

  // "skelgraph-gesture-classifier" version 1: labels, garbage, threshold, feature set, hands, trimmed,
  // pointing_correction {elevation_deg, azimuth_out_deg, shoulder_offset_m?, hand_offset_m?} (optional, default 0),
  // models (each a skelgraph-hmm with its class index and the action it was trained on).
  nlohmann::json to_json() const;
  static Classifier from_json(const nlohmann::json& j);  // throws ModelError naming the field
  void save(const std::string& path) const;
  static Classifier load(const std::string& path);

 private:
  std::vector<std::string> labels_;
  std::vector<Hmm> models_;
  std::vector<int> model_class_;
  std::vector<std::string> model_action_;
  int garbage_ = -1;
  Hands hands_ = Hands::Canonical;
  bool trimmed_ = true;
  PointingCorrection pointing_;
  double threshold_ = -1e300;
  FeatureSet features_ = FeatureSet::Thesis8;
};

// --- Evaluation ---

struct ClipResult {
  std::size_t clip = 0;  // index into the clips
  int truth = -1;
  Decision decision;
  int fold = 0;
};

struct RocPoint {
  double threshold;
  double tpr, fpr;
};

struct Metrics {
  std::vector<std::string> labels;
  std::vector<std::vector<int>> confusion;  // [truth][predicted], labelled clips only, no rejection
  double accuracy = 0.0;                    // labelled clips, no rejection (the thesis's measure)
  std::vector<double> precision, recall, f1;
  // With rejection: labelled clips correctly classified and accepted; unlabelled ones rejected.
  double accuracy_with_rejection = 0.0;
  int rejected_labelled = 0, unlabelled = 0, unlabelled_rejected = 0;
  // Detection of the first class: score = its log-likelihood per frame minus the best other's.
  std::vector<RocPoint> detection_roc;
  double detection_auc = 0.0;
  // Rejection of unlabelled clips by the best score (empty without unlabelled clips).
  std::vector<RocPoint> rejection_roc;
  double rejection_auc = 0.0;
};

Metrics evaluate(const std::vector<ClipResult>& results, const std::vector<std::string>& labels);
nlohmann::json to_json(const Metrics& m);
std::string confusion_text(const Metrics& m);
std::string confusion_svg(const Metrics& m, const std::string& title);

// Body size: the subjects sorted by arm length (the median of their clips')
// and cut in two halves; two folds: trained on the longer arms and tested on
// the shorter, and the reverse.
enum class Split { KFold, LeaveSubjectOut, BodySize };

struct CvOptions {
  Split split = Split::LeaveSubjectOut;
  int folds = 5;             // k-fold: stratified by label
  std::uint64_t seed = 1;
};

// Per-clip results from training on all folds but one, for every fold. `progress` (if set) is called after each fold.
std::vector<ClipResult> cross_validate(const std::vector<Clip>& clips, const ClassMap& map, const ClassifierOptions& options,
                                       const CvOptions& cv, const std::function<void(int done, int total)>& progress = {});

// Whether `a` beats `b` when choosing a configuration: accuracy, then the first
// class's F1, then the detection AUC.
bool better(const Metrics& a, const Metrics& b);

// Nested cross-validation, the honest figure for "try every configuration and
// keep the best": in each outer fold, every configuration is cross-validated
// (the same split) on that fold's training clips only, the best (`better`) is
// trained on all of them and scores the held-out fold. Outer folds run in
// parallel (the first configuration's `threads`).
struct NestedCv {
  std::vector<ClipResult> results;
  std::vector<int> chosen;  // per outer fold: index into the configurations
};
NestedCv nested_cross_validate(const std::vector<Clip>& clips, const ClassMap& map, const std::vector<ClassifierOptions>& configs,
                               const CvOptions& cv, const std::function<void(int done, int total)>& progress = {});

}  // namespace skelgraph::gesture
