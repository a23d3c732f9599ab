#include "skelgraph/gesture/metrics.hpp"
#include "skelgraph/report/report.hpp"
#include "skelgraph/skeleton/json_number.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace skelgraph::gesture {

namespace {

std::vector<RocPoint> roc(std::vector<std::pair<double, bool>> scored, double* auc) {
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  double P = 0, N = 0;
  for (const auto& s : scored) (s.second ? P : N) += 1;
  std::vector<RocPoint> out{{std::numeric_limits<double>::infinity(), 0.0, 0.0}};
  double tp = 0, fp = 0;
  *auc = 0.0;
  for (std::size_t i = 0; i < scored.size(); ++i) {
    (scored[i].second ? tp : fp) += 1;
    if (i + 1 < scored.size() && scored[i + 1].first == scored[i].first) continue;
    const RocPoint p{scored[i].first, P > 0 ? tp / P : 0.0, N > 0 ? fp / N : 0.0};
    *auc += (p.fpr - out.back().fpr) * (p.tpr + out.back().tpr) / 2;
    out.push_back(p);
  }
  if (P == 0 || N == 0) *auc = std::nan("");
  return out;
}

}  // namespace

Metrics evaluate(const std::vector<ClipResult>& results, const std::vector<std::string>& labels) {
  Metrics m;
  m.labels = labels;
  const std::size_t K = labels.size();
  m.confusion.assign(K, std::vector<int>(K, 0));
  int labelled = 0, correct = 0, correct_accepted = 0;
  std::vector<std::pair<double, bool>> detection, rejection;
  for (const auto& r : results) {
    const auto& d = r.decision;
    const double best = d.scores[static_cast<std::size_t>(d.label)];
    if (r.truth >= 0) {
      ++labelled;
      ++m.confusion[static_cast<std::size_t>(r.truth)][static_cast<std::size_t>(d.label)];
      if (d.label == r.truth) {
        ++correct;
        if (!d.rejected) ++correct_accepted;
      }
      if (d.rejected) ++m.rejected_labelled;
      rejection.emplace_back(best, true);
    } else {
      ++m.unlabelled;
      if (d.rejected) ++m.unlabelled_rejected;
      rejection.emplace_back(best, false);
    }
    if (K > 1) {
      double other = -std::numeric_limits<double>::infinity();
      for (std::size_t k = 1; k < K; ++k) other = std::max(other, d.scores[k]);
      detection.emplace_back(d.scores[0] - other, r.truth == 0);
    }
  }
  m.accuracy = labelled ? static_cast<double>(correct) / labelled : 0.0;
  const int total = labelled + m.unlabelled;
  m.accuracy_with_rejection = total ? static_cast<double>(correct_accepted + m.unlabelled_rejected) / total : 0.0;
  for (std::size_t k = 0; k < K; ++k) {
    int tp = m.confusion[k][k], predicted = 0, actual = 0;
    for (std::size_t j = 0; j < K; ++j) {
      predicted += m.confusion[j][k];
      actual += m.confusion[k][j];
    }
    const double p = predicted ? static_cast<double>(tp) / predicted : 0.0;
    const double rc = actual ? static_cast<double>(tp) / actual : 0.0;
    m.precision.push_back(p);
    m.recall.push_back(rc);
    m.f1.push_back(p + rc > 0 ? 2 * p * rc / (p + rc) : 0.0);
  }
  if (K > 1) m.detection_roc = roc(detection, &m.detection_auc);
  if (m.unlabelled > 0) m.rejection_roc = roc(rejection, &m.rejection_auc);
  return m;
}

namespace {
nlohmann::json roc_json(const std::vector<RocPoint>& r) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& p : r) a.push_back({std::isfinite(p.threshold) ? nlohmann::json(p.threshold) : nlohmann::json(nullptr), p.tpr, p.fpr});
  return a;
}
}  // namespace

nlohmann::json to_json(const Metrics& m) {
  nlohmann::json per = nlohmann::json::object();
  for (std::size_t k = 0; k < m.labels.size(); ++k)
    per[m.labels[k]] = {{"precision", m.precision[k]}, {"recall", m.recall[k]}, {"f1", m.f1[k]}};
  nlohmann::json j{{"labels", m.labels},
                   {"confusion", m.confusion},
                   {"accuracy", m.accuracy},
                   {"per_class", per},
                   {"with_rejection", {{"accuracy", m.accuracy_with_rejection},
                                       {"labelled_rejected", m.rejected_labelled},
                                       {"unlabelled", m.unlabelled},
                                       {"unlabelled_rejected", m.unlabelled_rejected}}}};
  if (!m.detection_roc.empty())
    j["detection"] = {{"class", m.labels[0]}, {"auc", json_number(m.detection_auc)}, {"roc_threshold_tpr_fpr", roc_json(m.detection_roc)}};
  if (!m.rejection_roc.empty()) j["rejection"] = {{"auc", json_number(m.rejection_auc)}, {"roc_threshold_tpr_fpr", roc_json(m.rejection_roc)}};
  return j;
}

std::string confusion_text(const Metrics& m) {
  std::size_t w = 6;
  for (const auto& l : m.labels) w = std::max(w, l.size() + 1);
  std::ostringstream s;
  s << std::string(w, ' ');
  for (const auto& l : m.labels) s << std::string(w - l.size(), ' ') << l;
  s << "   recall\n";
  for (std::size_t i = 0; i < m.labels.size(); ++i) {
    s << m.labels[i] << std::string(w - m.labels[i].size(), ' ');
    for (std::size_t j = 0; j < m.labels.size(); ++j) {
      const auto v = std::to_string(m.confusion[i][j]);
      s << std::string(w - v.size(), ' ') << v;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "   %.3f\n", m.recall[i]);
    s << buf;
  }
  s << "precision" << std::string(w > 9 ? w - 9 : 0, ' ');
  for (std::size_t j = 0; j < m.labels.size(); ++j) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%*.3f", static_cast<int>(w), m.precision[j]);
    s << buf;
  }
  s << "\n";
  return s.str();
}

std::string confusion_svg(const Metrics& m, const std::string& title) {
  char acc[64];
  std::snprintf(acc, sizeof acc, " (accuracy %.1f %%)", 100 * m.accuracy);
  return report::confusion_matrix(title + acc, m.labels, m.confusion);
}

}  // namespace skelgraph::gesture
