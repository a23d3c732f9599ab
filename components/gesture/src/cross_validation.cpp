#include "skelgraph/gesture/cross_validation.hpp"
#include "skelgraph/skeleton/stats.hpp"

#include "classifier_internal.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <random>
#include <tuple>

namespace skelgraph::gesture {

using detail::decide;
using detail::parallel_for;
using detail::prepared;
using detail::quantile;
using detail::train_models;

namespace {

// Fold of each clip (0..folds-1) under the split.
std::vector<int> assign_folds(const std::vector<Clip>& clips, const CvOptions& cv, int* folds_out) {
  std::vector<int> fold(clips.size(), 0);
  int folds = 0;
  if (cv.split == Split::BodySize) {
    std::map<std::string, std::vector<double>> arms;
    for (const auto& c : clips)
      if (std::isfinite(c.arm_length_m)) arms[c.subject].push_back(c.arm_length_m);
    std::vector<std::pair<double, std::string>> by_size;
    for (const auto& c : clips) arms.emplace(c.subject, std::vector<double>{});
    for (auto& [s, v] : arms) {
      if (v.empty()) throw ModelError("size split: subject '" + s + "' has no clip with both arms' joints to measure");
      by_size.emplace_back(stats::median(v), s);
    }
    if (by_size.size() < 2) throw ModelError("the size split needs clips of at least 2 subjects");
    std::sort(by_size.begin(), by_size.end());
    std::map<std::string, int> half;
    for (std::size_t i = 0; i < by_size.size(); ++i) half[by_size[i].second] = 2 * i < by_size.size() ? 0 : 1;
    for (std::size_t i = 0; i < clips.size(); ++i) fold[i] = half[clips[i].subject];
    *folds_out = 2;
    return fold;
  }
  if (cv.split == Split::LeaveSubjectOut) {
    std::map<std::string, int> subjects;
    for (const auto& c : clips) subjects.emplace(c.subject, 0);
    for (auto& [s, i] : subjects) i = folds++;
    if (folds < 2) throw ModelError("leave-subject-out needs clips of at least 2 subjects");
    for (std::size_t i = 0; i < clips.size(); ++i) fold[i] = subjects[clips[i].subject];
  } else {
    if (cv.folds < 2) throw ModelError("k-fold needs at least 2 folds");
    folds = cv.folds;
    std::mt19937_64 rng(cv.seed);
    std::map<int, std::vector<std::size_t>> by_label;
    for (std::size_t i = 0; i < clips.size(); ++i) by_label[clips[i].label].push_back(i);
    int next = 0;  // continue round-robin across labels so fold sizes stay even
    for (auto& [label, idx] : by_label) {
      std::shuffle(idx.begin(), idx.end(), rng);
      for (std::size_t i : idx) fold[i] = next++ % folds;
    }
  }
  *folds_out = folds;
  return fold;
}

// The nearest-neighbour experiment's fold: each held-out clip scores, per
// class, minus its DTW distance to that class's nearest training clip.
std::vector<ClipResult> run_fold_nearest(const std::vector<Clip>& clips, const std::vector<int>& fold, int f,
                                         const ClassMap& map, const ClassifierOptions& o) {
  std::vector<Sequence> train;
  std::vector<int> label;
  for (std::size_t i = 0; i < clips.size(); ++i)
    if (fold[i] != f && clips[i].label >= 0) {
      train.push_back(prepared(clips[i].x, o.hands, o.features.set));
      label.push_back(clips[i].label);
    }
  if (train.empty()) throw ModelError("nearest: no training clips in a fold");
  // Standardise every feature over the training frames.
  const auto d = train.front().cols();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(d), sq = Eigen::VectorXd::Zero(d);
  double n = 0;
  for (const auto& x : train) {
    mean += x.colwise().sum().transpose();
    sq += x.array().square().colwise().sum().matrix().transpose();
    n += static_cast<double>(x.rows());
  }
  mean /= n;
  Eigen::VectorXd sd = (sq / n - mean.cwiseProduct(mean)).cwiseMax(0).cwiseSqrt();
  for (Eigen::Index k = 0; k < d; ++k)
    if (sd[k] < 1e-9) sd[k] = 1;
  const auto standard = [&](Sequence x) {
    for (Eigen::Index r = 0; r < x.rows(); ++r) x.row(r) = (x.row(r).transpose() - mean).cwiseQuotient(sd).transpose();
    return x;
  };
  for (auto& x : train) x = standard(x);
  const auto K = map.classes.size();
  const auto score = [&](const Sequence& x, std::size_t skip) {
    std::vector<double> s(K, -std::numeric_limits<double>::infinity());
    for (std::size_t t = 0; t < train.size(); ++t) {
      if (t == skip) continue;
      auto& v = s[static_cast<std::size_t>(label[t])];
      v = std::max(v, -dtw_distance(x, train[t], o.nearest_band));
    }
    return s;
  };
  const auto decision = [&](std::vector<double> s, double threshold) {
    Decision dd;
    dd.scores = std::move(s);
    const auto best = std::max_element(dd.scores.begin(), dd.scores.end());
    dd.label = static_cast<int>(best - dd.scores.begin());
    double second = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < K; ++k)
      if (static_cast<int>(k) != dd.label) second = std::max(second, dd.scores[k]);
    dd.margin = K > 1 ? *best - second : 0.0;
    dd.rejected = dd.label != map.garbage_index() && (!std::isfinite(*best) || *best < threshold);
    return dd;
  };
  // The threshold: each training clip's score against the others (leave one out).
  std::vector<double> own;
  for (std::size_t t = 0; t < train.size(); ++t)
    if (label[t] != map.garbage_index()) own.push_back(score(train[t], t)[static_cast<std::size_t>(label[t])]);
  const double threshold = quantile(own, o.reject_quantile);
  std::vector<ClipResult> out;
  for (std::size_t i = 0; i < clips.size(); ++i)
    if (fold[i] == f)
      out.push_back({i, clips[i].label,
                     decision(score(standard(prepared(clips[i].x, o.hands, o.features.set)), train.size()), threshold), f});
  return out;
}

// Train on the clips outside fold f, score those in it (one thread).
std::vector<ClipResult> run_fold(const std::vector<Clip>& clips, const std::vector<int>& fold, int f, const ClassMap& map,
                                 const ClassifierOptions& o) {
  if (o.nearest) return run_fold_nearest(clips, fold, f, map, o);
  ClassifierOptions one = o;
  one.threads = 1;
  std::vector<const Clip*> train;
  for (std::size_t i = 0; i < clips.size(); ++i)
    if (fold[i] != f) train.push_back(&clips[i]);
  const auto models = train_models(train, map, one);
  const int K = static_cast<int>(map.classes.size());
  const auto run = [&](const Sequence& x, double threshold) {
    return decide(models.hmms, models.cls, K, x, o.hands, o.features.set, threshold, map.garbage_index());
  };
  // The threshold in cross-validation: training scores (no inner folds, to keep it affordable).
  std::vector<double> own;
  for (const Clip* c : train)
    if (c->label >= 0 && c->label != map.garbage_index()) own.push_back(run(c->x, 0).scores[static_cast<std::size_t>(c->label)]);
  const double threshold = quantile(own, o.reject_quantile);
  std::vector<ClipResult> out;
  for (std::size_t i = 0; i < clips.size(); ++i)
    if (fold[i] == f) out.push_back({i, clips[i].label, run(clips[i].x, threshold), f});
  return out;
}

std::vector<ClipResult> merged(std::vector<std::vector<ClipResult>>& per_fold) {
  std::vector<ClipResult> out;
  for (auto& v : per_fold) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.clip < b.clip; });
  return out;
}

}  // namespace

double dtw_distance(const Sequence& a, const Sequence& b, double band) {
  const Eigen::Index n = a.rows(), m = b.rows();
  if (n == 0 || m == 0) return std::numeric_limits<double>::infinity();
  const Eigen::Index w = std::max<Eigen::Index>(std::abs(n - m), static_cast<Eigen::Index>(band * static_cast<double>(std::max(n, m))));
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> prev(static_cast<std::size_t>(m + 1), inf), cur(static_cast<std::size_t>(m + 1), inf);
  prev[0] = 0;
  for (Eigen::Index i = 1; i <= n; ++i) {
    std::fill(cur.begin(), cur.end(), inf);
    for (Eigen::Index j = std::max<Eigen::Index>(1, i - w); j <= std::min(m, i + w); ++j) {
      const double c = (a.row(i - 1) - b.row(j - 1)).norm();
      const auto ju = static_cast<std::size_t>(j);
      cur[ju] = c + std::min({prev[ju], prev[ju - 1], cur[ju - 1]});
    }
    std::swap(prev, cur);
  }
  return prev[static_cast<std::size_t>(m)] / static_cast<double>(n + m);
}

std::vector<ClipResult> cross_validate(const std::vector<Clip>& clips, const ClassMap& map, const ClassifierOptions& o,
                                       const CvOptions& cv, const std::function<void(int, int)>& progress) {
  int folds = 0;
  const auto fold = assign_folds(clips, cv, &folds);
  std::vector<std::vector<ClipResult>> per_fold(static_cast<std::size_t>(folds));
  std::atomic<int> done{0};
  std::mutex m;
  parallel_for(folds, o.threads, [&](int f) {
    per_fold[static_cast<std::size_t>(f)] = run_fold(clips, fold, f, map, o);
    std::lock_guard<std::mutex> lock(m);
    ++done;
    if (progress) progress(done, folds);
  });
  return merged(per_fold);
}

bool better(const Metrics& a, const Metrics& b) {
  const auto key = [](const Metrics& m) {
    return std::make_tuple(m.accuracy, m.f1.empty() ? 0.0 : m.f1[0], std::isfinite(m.detection_auc) ? m.detection_auc : 0.0);
  };
  return key(a) > key(b);
}

NestedCv nested_cross_validate(const std::vector<Clip>& clips, const ClassMap& map, const std::vector<ClassifierOptions>& configs,
                               const CvOptions& cv, const std::function<void(int, int)>& progress) {
  if (configs.empty()) throw ModelError("nested cross-validation needs at least one configuration");
  int folds = 0;
  const auto fold = assign_folds(clips, cv, &folds);
  NestedCv out;
  out.chosen.assign(static_cast<std::size_t>(folds), 0);
  std::vector<std::vector<ClipResult>> per_fold(static_cast<std::size_t>(folds));
  std::atomic<int> done{0};
  std::mutex m;
  parallel_for(folds, configs.front().threads, [&](int f) {
    // The inner cross-validation sees only this fold's training clips.
    std::vector<Clip> inner;
    for (std::size_t i = 0; i < clips.size(); ++i)
      if (fold[i] != f) inner.push_back(clips[i]);
    int inner_folds = 0;
    const auto inner_fold = assign_folds(inner, cv, &inner_folds);
    std::size_t best = 0;
    Metrics best_metrics;
    for (std::size_t c = 0; c < configs.size(); ++c) {
      std::vector<std::vector<ClipResult>> r(static_cast<std::size_t>(inner_folds));
      for (int g = 0; g < inner_folds; ++g) r[static_cast<std::size_t>(g)] = run_fold(inner, inner_fold, g, map, configs[c]);
      const auto metrics = evaluate(merged(r), map.classes);
      if (c == 0 || better(metrics, best_metrics)) best = c, best_metrics = metrics;
    }
    per_fold[static_cast<std::size_t>(f)] = run_fold(clips, fold, f, map, configs[best]);
    std::lock_guard<std::mutex> lock(m);
    out.chosen[static_cast<std::size_t>(f)] = static_cast<int>(best);
    ++done;
    if (progress) progress(done, folds);
  });
  out.results = merged(per_fold);
  return out;
}

}  // namespace skelgraph::gesture
