#pragma once
// Cross-validation of the classifier: stratified k-fold, leave-subject-out and
// the body-size split, nested cross-validation over configurations, and the
// nearest-neighbour (DTW) experiment beside the HMMs. No DDS.

#include <cstdint>
#include <functional>
#include <vector>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/metrics.hpp"

namespace skelgraph::gesture {

// Dynamic time warping: the Euclidean frame distances summed along the best
// alignment within a band of `band` x the longer length (at least their
// difference), divided by the two lengths' sum. +inf when either is empty.
double dtw_distance(const Sequence& a, const Sequence& b, double band);

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
