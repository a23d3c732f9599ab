#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/skeleton/json_number.hpp"
#include "skelgraph/skeleton/stats.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <mutex>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

#include <yaml-cpp/yaml.h>

namespace skelgraph::gesture {

namespace {

// Runs f(i) for i in [0, n) on up to `threads` threads; the first exception is rethrown.
void parallel_for(int n, int threads, const std::function<void(int)>& f) {
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex m;
  auto worker = [&] {
    for (int i; (i = next++) < n;) {
      try {
        f(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, n); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return -1e300;
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

// The sequence a model sees: the clip, right-handed when asked, its active arm only for one-arm sets.
Sequence prepared(const Sequence& x, Hands hands, FeatureSet set) {
  return model_view(hands == Hands::Canonical ? right_handed(x, set) : x, set);
}

struct Models {
  std::vector<Hmm> hmms;
  std::vector<int> cls;             // class of each model
  std::vector<std::string> action;  // action it was trained on ("" when per class)
};

// Models only, no threshold.
Models train_models(const std::vector<const Clip*>& clips, const ClassMap& map, const ClassifierOptions& o) {
  if (one_arm(o.features.set) && o.hands != Hands::Canonical)
    throw ModelError(std::string("the '") + feature_set_name(o.features.set) +
                     "' features model the active arm only, which needs --hands canonical (the clip made right-handed)");
  // One group of sequences per model, in class order, then action order.
  std::map<std::pair<int, std::string>, std::vector<Sequence>> groups;
  for (const Clip* c : clips) {
    if (c->label < 0) continue;
    auto& g = groups[{c->label, o.per_action ? c->action : std::string()}];
    g.push_back(prepared(c->x, o.hands, o.features.set));
    if (o.hands == Hands::Augment) g.push_back(mirrored(c->x, o.features.set));  // (one-arm sets are refused above)
    if (o.prefixes)  // what a live spotter sees before the gesture ends
      for (double share : {0.5, 0.7}) {
        const auto n = static_cast<Eigen::Index>(share * static_cast<double>(c->x.rows()));
        if (n >= 5) g.push_back(prepared(Sequence(c->x.topRows(n)), o.hands, o.features.set));
      }
  }
  for (int k = 0; k < static_cast<int>(map.classes.size()); ++k)
    if (groups.lower_bound({k, std::string()}) == groups.end() || groups.lower_bound({k, std::string()})->first.first != k)
      throw ModelError("training: no clips of class '" + map.classes[static_cast<std::size_t>(k)] + "'");
  Models m;
  std::vector<const std::vector<Sequence>*> data;
  for (const auto& [key, seqs] : groups) {
    m.cls.push_back(key.first);
    m.action.push_back(key.second);
    data.push_back(&seqs);
  }
  // One spread for features that never vary in a model's clips, shared by
  // every model: their spread over all the training clips (or, constant
  // everywhere, the features' mean), so such a feature shifts no model's
  // score against another's.
  std::vector<const Sequence*> every_clip;
  for (const auto* seqs : data)
    for (const auto& x : *seqs) every_clip.push_back(&x);
  const Eigen::VectorXd shared_spread = feature_spread(every_clip);
  m.hmms.resize(data.size());
  parallel_for(static_cast<int>(data.size()), o.threads, [&](int i) {
    const auto iu = static_cast<std::size_t>(i);
    TrainOptions t = o.hmm;
    t.constant_spread = shared_spread;
    if (m.cls[iu] == map.garbage_index() && o.garbage_mixtures > 0) t.mixtures = o.garbage_mixtures;
    t.seed = o.hmm.seed + static_cast<std::uint64_t>(i);
    m.hmms[iu] = Hmm::train(*data[iu], t);
  });
  return m;
}

// Per class: the best log-likelihood per frame of its models.
Decision decide(const std::vector<Hmm>& hmms, const std::vector<int>& cls, int classes, const Sequence& raw, Hands hands,
                FeatureSet set, double threshold, int garbage) {
  const Sequence x = prepared(raw, hands, set);
  Decision d;
  d.scores.assign(static_cast<std::size_t>(classes), -std::numeric_limits<double>::infinity());
  const double T = std::max<double>(1.0, static_cast<double>(x.rows()));
  for (std::size_t i = 0; i < hmms.size(); ++i) {
    auto& s = d.scores[static_cast<std::size_t>(cls[i])];
    s = std::max(s, hmms[i].log_likelihood(x) / T);
  }
  const auto best = std::max_element(d.scores.begin(), d.scores.end());
  d.label = static_cast<int>(best - d.scores.begin());
  double second = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < d.scores.size(); ++k)
    if (static_cast<int>(k) != d.label) second = std::max(second, d.scores[k]);
  d.margin = d.scores.size() > 1 ? *best - second : 0.0;
  d.rejected = d.label != garbage && (!std::isfinite(*best) || *best < threshold);
  return d;
}

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

std::optional<Hands> hands_from_name(const std::string& name) {
  if (name == "canonical") return Hands::Canonical;
  if (name == "augment") return Hands::Augment;
  if (name == "as-is") return Hands::AsIs;
  return std::nullopt;
}

const char* hands_name(Hands h) {
  switch (h) {
    case Hands::Canonical: return "canonical";
    case Hands::Augment: return "augment";
    case Hands::AsIs: return "as-is";
  }
  return "?";
}

// --- Class maps ---

const std::vector<std::string>& ClassMap::preset_names() {
  static const std::vector<std::string> names{"two-class", "five-class", "robot"};
  return names;
}

ClassMap ClassMap::preset(const std::string& name) {
  ClassMap m;
  if (name == "two-class") {
    m.classes = {"point", "other"};
    m.action_class = {{"Point-at-the-camera", "point"}};
    m.garbage = "other";
  } else if (name == "five-class") {
    m.classes = {"point", "reach", "walk", "overhead", "wave"};
    m.action_class = {{"Point-at-the-camera", "point"},
                      {"Push-an-imaginary-button-in-front-of-you", "reach"},
                      {"Walk-in-place", "walk"},
                      {"Raise-your-hand", "overhead"},
                      {"Wave-your-hand", "wave"}};
  } else if (name == "robot") {
    // A robot cell's commands: point (fetch), stop (a raised palm), come here, wave; the rest rejected.
    m.classes = {"point", "stop", "come_here", "wave", "other"};
    m.action_class = {{"Point-at-the-camera", "point"},
                      {"Signal-someone-to-stop", "stop"},
                      {"Signal-someone-to-come-here", "come_here"},
                      {"Wave-your-hand", "wave"},
                      {"Wave-your-other-hand", "wave"}};
    m.garbage = "other";
  } else {
    throw ModelError("unknown class preset '" + name + "' (expected two-class, five-class, robot or a YAML file)");
  }
  return m;
}

ClassMap ClassMap::load(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ModelError(path + ": " + e.what());
  }
  const auto where = [&](const YAML::Node& n) { return path + ":" + std::to_string(n.Mark().line + 1); };
  if (!root.IsMap() || !root["classes"] || !root["classes"].IsMap() || root["classes"].size() == 0)
    throw ModelError(path + ": expected a map with 'classes: {name: [action, ...], ...}'");
  ClassMap m;
  for (const auto& kv : root["classes"]) {
    const auto name = kv.first.as<std::string>();
    if (!kv.second.IsSequence() || kv.second.size() == 0)
      throw ModelError(where(kv.second) + ": class '" + name + "' needs a non-empty list of actions");
    m.classes.push_back(name);
    for (const auto& a : kv.second) {
      const auto action = a.as<std::string>();
      if (!m.action_class.emplace(action, name).second)
        throw ModelError(where(a) + ": action '" + action + "' is in two classes");
    }
  }
  for (const auto& kv : root) {
    const auto key = kv.first.as<std::string>();
    if (key != "classes" && key != "garbage") throw ModelError(where(kv.first) + ": unknown key '" + key + "' (expected classes, garbage)");
  }
  if (root["garbage"]) {
    m.garbage = root["garbage"].as<std::string>();
    if (std::find(m.classes.begin(), m.classes.end(), m.garbage) != m.classes.end())
      throw ModelError(where(root["garbage"]) + ": the garbage class '" + m.garbage + "' must not also list actions");
    m.classes.push_back(m.garbage);
  }
  return m;
}

std::optional<int> ClassMap::label_of(const std::string& action) const {
  const auto it = action_class.find(action);
  const std::string& c = it != action_class.end() ? it->second : garbage;
  if (c.empty()) return std::nullopt;
  return static_cast<int>(std::find(classes.begin(), classes.end(), c) - classes.begin());
}

int ClassMap::garbage_index() const { return garbage.empty() ? -1 : static_cast<int>(classes.size()) - 1; }

nlohmann::json ClassMap::to_json() const {
  nlohmann::json c = nlohmann::json::object();
  for (const auto& name : classes) {
    if (name == garbage) continue;
    auto& list = c[name] = nlohmann::json::array();
    for (const auto& [a, k] : action_class)
      if (k == name) list.push_back(a);
  }
  nlohmann::json j{{"classes", c}};
  if (!garbage.empty()) j["garbage"] = garbage;
  return j;
}

// --- Classifier ---

Classifier Classifier::train(const std::vector<Clip>& clips, const ClassMap& map, const ClassifierOptions& o) {
  if (o.nearest) throw ModelError("the nearest-neighbour (DTW) classifier is a cross-validation experiment: it cannot be trained into a model yet");
  std::vector<const Clip*> all;
  for (const auto& c : clips) all.push_back(&c);
  Classifier c;
  c.labels_ = map.classes;
  c.garbage_ = map.garbage_index();
  c.features_ = o.features.set;
  c.hands_ = o.hands;
  c.trimmed_ = o.trimmed;
  auto m = train_models(all, map, o);
  c.models_ = std::move(m.hmms);
  c.model_class_ = std::move(m.cls);
  c.model_action_ = std::move(m.action);
  // Threshold: a low quantile of the clips' own-class scores, held out by inner folds when asked.
  std::vector<double> own;
  // Held-out scores need every class in every inner fold's training part.
  std::map<int, int> per_class;
  for (const auto& clip : clips)
    if (clip.label >= 0) ++per_class[clip.label];
  bool enough = true;
  for (const auto& [k, n] : per_class) enough = enough && n >= o.calibration_folds;
  if (o.calibration_folds >= 2 && enough) {
    ClassifierOptions inner = o;
    inner.calibration_folds = 0;
    CvOptions cv;
    cv.split = Split::KFold;
    cv.folds = o.calibration_folds;
    cv.seed = o.hmm.seed + 101;
    for (const auto& r : cross_validate(clips, map, inner, cv))
      if (r.truth >= 0 && r.truth != c.garbage_) own.push_back(r.decision.scores[static_cast<std::size_t>(r.truth)]);
  } else {
    for (const auto& clip : clips)
      if (clip.label >= 0 && clip.label != c.garbage_) own.push_back(c.classify(clip.x).scores[static_cast<std::size_t>(clip.label)]);
  }
  c.threshold_ = quantile(own, o.reject_quantile);
  return c;
}

Decision Classifier::classify(const Sequence& x) const {
  return decide(models_, model_class_, static_cast<int>(labels_.size()), x, hands_, features_, threshold_, garbage_);
}

nlohmann::json Classifier::to_json() const {
  nlohmann::json models = nlohmann::json::array();
  for (std::size_t i = 0; i < models_.size(); ++i)
    models.push_back({{"class", model_class_[i]}, {"action", model_action_[i]}, {"hmm", models_[i].to_json()}});
  return {{"format", "skelgraph-gesture-classifier"},
          {"version", 1},
          {"labels", labels_},
          {"garbage", garbage_},
          {"threshold", threshold_},
          {"features", feature_set_name(features_)},
          {"hands", hands_name(hands_)},
          {"trimmed", trimmed_},
          {"pointing_correction",
           {{"elevation_deg", pointing_.elevation},
            {"azimuth_out_deg", pointing_.azimuth_out},
            {"shoulder_offset_m", {pointing_.shoulder.x(), pointing_.shoulder.y(), pointing_.shoulder.z()}},
            {"hand_offset_m", {pointing_.hand.x(), pointing_.hand.y(), pointing_.hand.z()}}}},
          {"models", models}};
}

Classifier Classifier::from_json(const nlohmann::json& j) {
  const auto need = [&](const char* key) -> const nlohmann::json& {
    if (!j.is_object() || !j.contains(key)) throw ModelError(std::string("classifier: missing field '") + key + "'");
    return j.at(key);
  };
  if (need("format") != "skelgraph-gesture-classifier") throw ModelError("classifier: 'format' is not skelgraph-gesture-classifier");
  if (need("version") != 1) throw ModelError("classifier: unsupported 'version' " + need("version").dump() + " (this build reads 1)");
  Classifier c;
  try {
    c.labels_ = need("labels").get<std::vector<std::string>>();
    c.garbage_ = need("garbage").get<int>();
    c.threshold_ = need("threshold").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw ModelError(std::string("classifier: ") + e.what());
  }
  const auto set = feature_set_from_name(need("features").is_string() ? need("features").get<std::string>() : "");
  if (!set) throw ModelError("classifier: 'features' must be thesis8, extended, body, hands or arm");
  c.features_ = *set;
  const auto hands = hands_from_name(need("hands").is_string() ? need("hands").get<std::string>() : "");
  if (!hands) throw ModelError("classifier: 'hands' must be canonical, augment or as-is");
  c.hands_ = *hands;
  if (one_arm(c.features_) && c.hands_ != Hands::Canonical)
    throw ModelError(std::string("classifier: '") + feature_set_name(c.features_) + "' models need 'hands': \"canonical\"");
  if (!need("trimmed").is_boolean()) throw ModelError("classifier: 'trimmed' must be true or false");
  c.trimmed_ = need("trimmed").get<bool>();
  if (j.contains("pointing_correction")) {
    const auto& p = j["pointing_correction"];
    if (!p.is_object() || !p.contains("elevation_deg") || !p["elevation_deg"].is_number() || !p.contains("azimuth_out_deg") ||
        !p["azimuth_out_deg"].is_number())
      throw ModelError("classifier: 'pointing_correction' must be {elevation_deg: number, azimuth_out_deg: number}");
    c.pointing_.elevation = p["elevation_deg"].get<double>();
    c.pointing_.azimuth_out = p["azimuth_out_deg"].get<double>();
    for (const auto& [key, out] : {std::pair{"shoulder_offset_m", &c.pointing_.shoulder}, {"hand_offset_m", &c.pointing_.hand}}) {
      if (!p.contains(key)) continue;  // models written before the joint offsets: none
      const auto& v = p[key];
      if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
        throw ModelError(std::string("classifier: 'pointing_correction.") + key + "' must be [out, up, forward] in metres");
      *out = Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    }
  }
  const int K = static_cast<int>(c.labels_.size());
  if (c.garbage_ < -1 || c.garbage_ >= K) throw ModelError("classifier: 'garbage' is not a label index or -1");
  const auto& models = need("models");
  if (!models.is_array() || models.empty()) throw ModelError("classifier: 'models' must be a non-empty array");
  const int dim = static_cast<int>(model_columns(c.features_).size());
  std::vector<bool> has(static_cast<std::size_t>(K), false);
  for (std::size_t i = 0; i < models.size(); ++i) {
    const std::string where = "classifier: models[" + std::to_string(i) + "]";
    const auto& e = models[i];
    if (!e.is_object() || !e.contains("class") || !e["class"].is_number_integer() || !e.contains("hmm"))
      throw ModelError(where + ": expected {class: index, action: name, hmm: model}");
    const int k = e["class"].get<int>();
    if (k < 0 || k >= K) throw ModelError(where + ": 'class' " + std::to_string(k) + " is not a label index");
    try {
      c.models_.push_back(Hmm::from_json(e["hmm"]));
    } catch (const ModelError& err) {
      throw ModelError(where + " (" + c.labels_[static_cast<std::size_t>(k)] + "): " + err.what());
    }
    if (c.models_.back().dim() != dim)
      throw ModelError(where + " has " + std::to_string(c.models_.back().dim()) + " features; '" + feature_set_name(c.features_) +
                       "' models have " + std::to_string(dim));
    c.model_class_.push_back(k);
    c.model_action_.push_back(e.value("action", std::string()));
    has[static_cast<std::size_t>(k)] = true;
  }
  for (int k = 0; k < K; ++k)
    if (!has[static_cast<std::size_t>(k)]) throw ModelError("classifier: no model for label '" + c.labels_[static_cast<std::size_t>(k)] + "'");
  return c;
}

void Classifier::save(const std::string& path) const {
  std::ofstream f(path);
  if (!f) throw ModelError("cannot write " + path);
  f << to_json().dump(1) << '\n';
  if (!f) throw ModelError("cannot write " + path);
}

nlohmann::json read_model_json(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw ModelError("cannot read " + path);
  try {
    return nlohmann::json::parse(f);
  } catch (const nlohmann::json::exception& e) {
    throw ModelError(path + ": not JSON: " + e.what());
  }
}

Classifier Classifier::load(const std::string& path) {
  const auto j = read_model_json(path);
  try {
    return from_json(j);
  } catch (const ModelError& e) {
    throw ModelError(path + ": " + e.what());
  }
}

// --- Cross-validation ---

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

// --- Metrics ---

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
  const int K = static_cast<int>(m.labels.size()), cell = 56, left = 130, top = 120;
  const int width = left + K * cell + 20, height = top + K * cell + 50;
  const auto esc = [](const std::string& t) {
    std::string o;
    for (char c : t) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
    return o;
  };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  char acc[64];
  std::snprintf(acc, sizeof acc, " (accuracy %.1f %%)", 100 * m.accuracy);
  s << "<text x=\"10\" y=\"20\" font-size=\"14\">" << esc(title) << acc << "</text>\n";
  s << "<text x=\"" << left + K * cell / 2 << "\" y=\"45\" text-anchor=\"middle\">predicted</text>\n";
  s << "<text x=\"15\" y=\"" << top + K * cell / 2 << "\" transform=\"rotate(-90 15 " << top + K * cell / 2
    << ")\" text-anchor=\"middle\">true</text>\n";
  for (int i = 0; i < K; ++i) {
    int row = 0;
    for (int j = 0; j < K; ++j) row += m.confusion[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
    s << "<text x=\"" << left - 6 << "\" y=\"" << top + i * cell + cell / 2 + 4 << "\" text-anchor=\"end\">" << esc(m.labels[static_cast<std::size_t>(i)]) << "</text>\n";
    const int x = left + i * cell + cell / 2;
    s << "<text x=\"" << x << "\" y=\"" << top - 6 << "\" transform=\"rotate(-45 " << x << ' ' << top - 6 << ")\">" << esc(m.labels[static_cast<std::size_t>(i)]) << "</text>\n";
    for (int j = 0; j < K; ++j) {
      const int v = m.confusion[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      const double share = row ? static_cast<double>(v) / row : 0.0;
      const int shade = static_cast<int>(255 - 200 * share);
      s << "<rect x=\"" << left + j * cell << "\" y=\"" << top + i * cell << "\" width=\"" << cell << "\" height=\"" << cell
        << "\" fill=\"rgb(" << shade << ',' << shade << ",255)\" stroke=\"#888\"/>\n";
      s << "<text x=\"" << left + j * cell + cell / 2 << "\" y=\"" << top + i * cell + cell / 2 + 4 << "\" text-anchor=\"middle\" fill=\""
        << (share > 0.6 ? "white" : "black") << "\">" << v << "</text>\n";
    }
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace skelgraph::gesture
