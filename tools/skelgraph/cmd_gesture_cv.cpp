// skelgraph gesture cv: cross-validation of clip classifiers (one
// configuration, a sweep with the winner by accuracy, nested), printed or as JSON.

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

namespace {

struct CvRun {
  ClassifierOptions config;
  Metrics metrics;
  std::vector<ClipResult> results;
};

CvRun run_cv(const GestureOptions& o, const ClassMap& map, const std::vector<Clip>& clips, const ClassifierOptions& c,
             const std::string& what) {
  Progress progress;
  const auto results = cross_validate(clips, map, c, cv_options(o), [&](int done, int total) {
    progress(what + ": fold " + std::to_string(done) + "/" + std::to_string(total), done == total);
  });
  return {c, evaluate(results, map.classes), results};
}

}  // namespace

CvOptions cv_options(const GestureOptions& o) {
  CvOptions cv;
  cv.split = o.split == "kfold" ? Split::KFold : o.split == "size" ? Split::BodySize : Split::LeaveSubjectOut;
  cv.folds = o.folds;
  cv.seed = o.seed;
  return cv;
}

int gesture_cv(const GestureOptions& o) {
  if (o.spot_streams) return gesture_cv_streams(o);
  const auto map = class_map(o.classes);
  const auto base = chosen_classifier_options(o);
  BadInputs bad;
  const auto clips = load(o, map, base, bad);
  std::vector<ClassifierOptions> configs;
  if (o.sweep) {
    const std::vector<int> states = o.sweep_states.empty() ? std::vector<int>{3, 5, 7, 9} : o.sweep_states;
    const std::vector<int> mixtures = o.sweep_mixtures.empty() ? std::vector<int>{1, 2, 3} : o.sweep_mixtures;
    const std::vector<std::string> covs = o.sweep_covariance.empty() ? std::vector<std::string>{"full", "diag"} : o.sweep_covariance;
    const std::vector<std::string> inits = o.sweep_init.empty() ? std::vector<std::string>{o.init} : o.sweep_init;
    for (const auto& init : inits)
      for (const auto& cov : covs)
        for (int s : states)
          for (int m : mixtures) {
            auto c = base;
            c.hmm.states = s;
            c.hmm.mixtures = m;
            c.hmm.covariance = cov == "diag" ? Covariance::Diagonal : Covariance::Full;
            c.hmm.init = init == "kmeans" ? Init::KMeans : Init::Segments;
            configs.push_back(c);
          }
  } else {
    configs.push_back(base);
  }
  const auto config_name = [](const ClassifierOptions& c) {
    return std::to_string(c.hmm.states) + " states, " + std::to_string(c.hmm.mixtures) + " mixtures, " +
           (c.hmm.covariance == Covariance::Full ? "full" : "diag") + ", " + init_name(c.hmm.init) + " init";
  };
  std::vector<CvRun> runs;
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const auto& c = configs[i];
    const std::string what = "config " + std::to_string(i + 1) + "/" + std::to_string(configs.size()) + " (" + config_name(c) + ")";
    runs.push_back(run_cv(o, map, clips, c, what));
  }
  // The winner: accuracy, then the first class's F1, then detection AUC.
  std::size_t best = 0;
  for (std::size_t i = 1; i < runs.size(); ++i)
    if (better(runs[i].metrics, runs[best].metrics)) best = i;
  // --nested: the same choice made inside each fold, scored on the held-out fold.
  std::optional<NestedCv> nested;
  Metrics nested_metrics;
  if (o.nested) {
    Progress progress;
    nested = nested_cross_validate(clips, map, configs, cv_options(o), [&](int done, int total) {
      progress("nested: outer fold " + std::to_string(done) + "/" + std::to_string(total), done == total);
    });
    nested_metrics = evaluate(nested->results, map.classes);
  }
  const auto& win = runs[best];
  const std::string split = o.split == "kfold" ? std::to_string(o.folds) + "-fold stratified"
                            : o.split == "size" ? "by body size (shorter arms vs longer, both ways)"
                                                : "leave-subject-out";
  if (!o.svg.empty()) {
    std::ofstream f(o.svg);
    f << confusion_svg(win.metrics, split + ", " + o.classes);
    if (!f) throw std::runtime_error("cannot write " + o.svg);
  }
  if (o.json) {
    nlohmann::json j{{"split", o.split == "kfold" ? "kfold" : o.split == "size" ? "size" : "leave-subject-out"},
                     {"folds", o.split == "kfold" ? o.folds : -1},
                     {"clips", clips.size()},
                     {"classes", map.to_json()},
                     {"config", config_json(win.config)},
                     {"metrics", to_json(win.metrics)}};
    if (o.split == "size") {  // what the halves were cut by
      std::map<std::string, std::vector<double>> arms;
      for (const auto& c : clips)
        if (std::isfinite(c.arm_length_m)) arms[c.subject].push_back(c.arm_length_m);
      auto& by = j["arm_length_m_by_subject"] = nlohmann::json::object();
      for (const auto& [subject, v] : arms) by[subject] = stats::median(v);
    }
    auto& per = j["clips"] = nlohmann::json::array();
    for (const auto& r : win.results) {
      const auto& clip = clips[r.clip];
      nlohmann::json scores = nlohmann::json::object();
      for (std::size_t k = 0; k < map.classes.size(); ++k) scores[map.classes[k]] = r.decision.scores[k];
      per.push_back({{"file", clip.source},
                     {"subject", clip.subject},
                     {"action", clip.action},
                     {"truth", r.truth >= 0 ? nlohmann::json(map.classes[static_cast<std::size_t>(r.truth)]) : nlohmann::json(nullptr)},
                     {"predicted", map.classes[static_cast<std::size_t>(r.decision.label)]},
                     {"rejected", r.decision.rejected},
                     {"fold", r.fold},
                     {"scores", scores}});
    }
    if (nested) {
      auto& n = j["nested"] = nlohmann::json::object();
      n["metrics"] = to_json(nested_metrics);
      auto& chosen = n["chosen"] = nlohmann::json::array();
      for (int c : nested->chosen) chosen.push_back(config_json(configs[static_cast<std::size_t>(c)]));
    }
    if (o.sweep) {
      auto& s = j["sweep"] = nlohmann::json::array();
      for (const auto& r : runs) {
        auto e = config_json(r.config);
        e["accuracy"] = r.metrics.accuracy;
        e["f1_" + map.classes[0]] = r.metrics.f1[0];
        // the last tie-breaker of the choice (null where there is no detection ROC)
        e["detection_auc"] = std::isfinite(r.metrics.detection_auc) ? nlohmann::json(r.metrics.detection_auc) : nlohmann::json();
        s.push_back(e);
      }
    }
    std::printf("%s\n", j.dump(2).c_str());
    return bad.exit_code(0, expand_paths(o.inputs).size());
  }
  if (o.sweep) {
    std::printf("%-6s %-7s %-9s %-9s %-9s %s\n", "states", "mixt.", "cov.", "init", "accuracy", ("F1 " + map.classes[0]).c_str());
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const auto& r = runs[i];
      std::printf("%-6d %-7d %-9s %-9s %-9s %.3f%s\n", r.config.hmm.states, r.config.hmm.mixtures,
                  r.config.hmm.covariance == Covariance::Full ? "full" : "diag", init_name(r.config.hmm.init),
                  pct(r.metrics.accuracy).c_str(), r.metrics.f1[0],
                  i == best ? "  <- best" : "");
    }
    std::printf("\nbest configuration:\n");
  }
  const auto& m = win.metrics;
  std::printf("%s, %zu clips, features %s, %d states, %d mixtures, %s covariance, %s initialisation%s\n", split.c_str(),
              clips.size(), feature_set_name(win.config.features.set), win.config.hmm.states, win.config.hmm.mixtures,
              win.config.hmm.covariance == Covariance::Full ? "full" : "diagonal", init_name(win.config.hmm.init),
              win.config.hmm.restarts > 1 ? (", best of " + std::to_string(win.config.hmm.restarts) + " restarts").c_str() : "");
  std::printf("%s", confusion_text(m).c_str());
  std::printf("accuracy %s", pct(m.accuracy).c_str());
  std::printf("; %s precision %.3f recall %.3f F1 %.3f", m.labels[0].c_str(), m.precision[0], m.recall[0], m.f1[0]);
  if (std::isfinite(m.detection_auc)) std::printf("; detection AUC %.3f", m.detection_auc);
  std::printf("\nwith rejection: accuracy %s (%d labelled clips rejected", pct(m.accuracy_with_rejection).c_str(), m.rejected_labelled);
  if (m.unlabelled) std::printf("; %d of %d clips in no class rejected; rejection AUC %.3f", m.unlabelled_rejected, m.unlabelled, m.rejection_auc);
  std::printf(")\n");
  if (nested) {
    const auto& n = nested_metrics;
    std::printf("\nnested cross-validation (the configuration chosen inside each fold, on its training subjects only):\n");
    std::map<std::string, int> count;
    for (int c : nested->chosen) ++count[config_name(configs[static_cast<std::size_t>(c)])];
    for (const auto& [name, k] : count) std::printf("  %s: chosen in %d of %zu folds\n", name.c_str(), k, nested->chosen.size());
    std::printf("%s", confusion_text(n).c_str());
    std::printf("accuracy %s; %s precision %.3f recall %.3f F1 %.3f\n", pct(n.accuracy).c_str(), n.labels[0].c_str(), n.precision[0],
                n.recall[0], n.f1[0]);
  }
  if (!o.svg.empty()) std::printf("confusion matrix written to %s\n", o.svg.c_str());
  return bad.exit_code(0, expand_paths(o.inputs).size());
}

}  // namespace skelgraph::cli::gesture_cmd
