#pragma once
// A classifier's decisions scored against the truth: confusion matrices,
// per-class precision/recall/F1 and ROC curves (detection of the first class,
// rejection of clips in no class). No DDS.

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skelgraph::gesture {

// A classifier's answer for one sequence (Classifier::classify).
struct Decision {
  int label = -1;                 // the best class
  bool rejected = false;          // its score is below the threshold: "no gesture"
  std::vector<double> scores;     // per class: log-likelihood per frame
  double margin = 0.0;            // best score minus the next best
};

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
std::string confusion_svg(const Metrics& m, const std::string& title);  // report::confusion_matrix, the title with the accuracy

}  // namespace skelgraph::gesture
