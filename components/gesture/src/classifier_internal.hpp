#pragma once
// What classifier.cpp and cross_validation.cpp share (private to the gesture
// core, not installed): the thread pool helper, the rejection threshold's
// quantile, the sequence a model sees, training the per-class models and the
// decision from their scores.

#include <functional>
#include <string>
#include <vector>

#include "skelgraph/gesture/classifier.hpp"

namespace skelgraph::gesture::detail {

// Runs f(i) for i in [0, n) on up to `threads` threads; the first exception is rethrown.
void parallel_for(int n, int threads, const std::function<void(int)>& f);

// The q quantile of v (linear between neighbours); -1e300 when v is empty.
double quantile(std::vector<double> v, double q);

// The sequence a model sees: the clip, right-handed when asked, its active arm only for one-arm sets.
Sequence prepared(const Sequence& x, Hands hands, FeatureSet set);

struct Models {
  std::vector<GaussianHmm> hmms;
  std::vector<int> cls;             // class of each model
  std::vector<std::string> action;  // action it was trained on ("" when per class)
};

// The models of every class (or every action of a class) on the labelled clips; no threshold.
Models train_models(const std::vector<const Clip*>& clips, const ClassMap& map, const ClassifierOptions& o);

// Per class: the best log-likelihood per frame of its models.
Decision decide(const std::vector<GaussianHmm>& hmms, const std::vector<int>& cls, int classes, const Sequence& raw, Hands hands,
                FeatureSet set, double threshold, int garbage);

}  // namespace skelgraph::gesture::detail
