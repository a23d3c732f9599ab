#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/cross_validation.hpp"

#include "classifier_internal.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

namespace skelgraph::gesture {

namespace detail {

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
    m.hmms[iu] = GaussianHmm::train(*data[iu], t);
  });
  return m;
}

// Per class: the best log-likelihood per frame of its models.
Decision decide(const std::vector<GaussianHmm>& hmms, const std::vector<int>& cls, int classes, const Sequence& raw, Hands hands,
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

}  // namespace detail

using detail::decide;
using detail::quantile;
using detail::train_models;

std::optional<Hands> hands_from_name(const std::string& name) {
  if (name == "canonical") return Hands::Canonical;
  if (name == "augment") return Hands::Augment;
  if (name == "as-is") return Hands::AsIs;
  return std::nullopt;
}

const char* init_name(Init i) { return i == Init::KMeans ? "kmeans" : "segments"; }

const char* hands_name(Hands h) {
  switch (h) {
    case Hands::Canonical: return "canonical";
    case Hands::Augment: return "augment";
    case Hands::AsIs: return "as-is";
  }
  return "?";
}

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
          {"operating_point", {{"min_confidence", operating_.min_confidence}, {"confirm_s", operating_.confirm_s}}},
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
  if (j.contains("operating_point")) {
    const auto& p = j["operating_point"];
    const auto number = [&](const char* key, double hi) {
      if (!p.is_object() || !p.contains(key) || !p[key].is_number() || p[key].get<double>() < 0 || p[key].get<double>() > hi)
        throw ModelError(std::string("classifier: 'operating_point.") + key + "' must be a number from 0 to " +
                         (hi == 1.0 ? "1" : "10"));
      return p[key].get<double>();
    };
    c.operating_.min_confidence = number("min_confidence", 1.0);
    c.operating_.confirm_s = number("confirm_s", 10.0);
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
      c.models_.push_back(GaussianHmm::from_json(e["hmm"]));
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

}  // namespace skelgraph::gesture
