#pragma once
// Gesture classification with one HMM per class: highest likelihood wins,
// an optional garbage class (everything that is not a gesture of interest,
// as the thesis's two-class setup), and a rejection threshold below which the
// answer is "no gesture". Class maps in class_map.hpp; confusion matrices,
// per-class precision/recall/F1 and ROC curves in metrics.hpp;
// cross-validation (stratified k-fold and leave-subject-out) in
// cross_validation.hpp, included at the end of this file. Eigen and std only:
// no DDS.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/gesture/class_map.hpp"
#include "skelgraph/gesture/features.hpp"
#include "skelgraph/gesture/gaussian_mixture.hpp"
#include "skelgraph/gesture/metrics.hpp"

namespace skelgraph::gesture {

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
const char* init_name(Init i);  // "kmeans", "segments"

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
  const std::vector<GaussianHmm>& models() const { return models_; }
  const std::vector<int>& model_classes() const { return model_class_; }  // the class of each model
  FeatureSet feature_set() const { return features_; }
  Hands hands() const { return hands_; }
  bool trimmed() const { return trimmed_; }
  const PointingCorrection& pointing_correction() const { return pointing_; }
  void set_pointing_correction(const PointingCorrection& p) { pointing_ = p; }
  // Where the model's events are cut, chosen for it (`gesture sim --min-confidence --confirm --out`): a spotter
  // with this model uses it unless told otherwise (SpotterOptions::min_confidence, confirm). Default 0, 0.
  struct OperatingPoint {
    double min_confidence = 0.0;  // events less sure than this are dropped, 0-1
    double confirm_s = 0.0;       // pointing held this long beyond the hold, 0-10 s
  };
  const OperatingPoint& operating_point() const { return operating_; }
  void set_operating_point(const OperatingPoint& p) { operating_ = p; }

  // "skelgraph-gesture-classifier" version 1: labels, garbage, threshold, feature set, hands, trimmed,
  // pointing_correction {elevation_deg, azimuth_out_deg, shoulder_offset_m?, hand_offset_m?} (optional, default 0),
  // operating_point {min_confidence, confirm_s} (optional, default 0),
  // models (each a skelgraph-hmm with its class index and the action it was trained on).
  nlohmann::json to_json() const;
  static Classifier from_json(const nlohmann::json& j);  // throws ModelError naming the field
  void save(const std::string& path) const;
  static Classifier load(const std::string& path);

 private:
  std::vector<std::string> labels_;
  std::vector<GaussianHmm> models_;
  std::vector<int> model_class_;
  std::vector<std::string> model_action_;
  int garbage_ = -1;
  Hands hands_ = Hands::Canonical;
  bool trimmed_ = true;
  PointingCorrection pointing_;
  OperatingPoint operating_;
  double threshold_ = -1e300;
  FeatureSet features_ = FeatureSet::Thesis8;
};

}  // namespace skelgraph::gesture

// Cross-validation (which needs the declarations above), for the files that
// include only this header.
#include "skelgraph/gesture/cross_validation.hpp"
