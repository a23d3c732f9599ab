#include "skelgraph/gesture/stream_spotting.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "skelgraph/gesture/dataset.hpp"

namespace skelgraph::gesture {

namespace {

std::int64_t ns(double s) { return static_cast<std::int64_t>(s * 1e9); }

constexpr double kNearOther = 0.3;  // s: a near-miss garbage window this close to an annotation is dropped

// The frames of the window that ends at frame `end` (inclusive): those newer than stamp[end] - window.
Sequence window_at(const AnnotatedStream& s, std::size_t end, double window_s) {
  const auto from = s.stamps[end] - ns(window_s);
  std::size_t begin = end;
  while (begin > 0 && s.stamps[begin - 1] > from) --begin;
  return s.x.middleRows(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(end - begin + 1));
}

// The last frame at or before t; false when t is before the first frame.
bool frame_at(const AnnotatedStream& s, std::int64_t t, std::size_t& out) {
  const auto it = std::upper_bound(s.stamps.begin(), s.stamps.end(), t);
  if (it == s.stamps.begin()) return false;
  out = static_cast<std::size_t>(it - s.stamps.begin()) - 1;
  return true;
}

}  // namespace

nlohmann::json StreamSpotOptions::to_json() const {
  return {{"window_s", window_s},         {"positive_offsets_s", positive_offsets_s}, {"negative_gap_s", negative_gap_s},
          {"negative_step_s", negative_step_s}, {"near_negative_offsets_s", near_negative_offsets_s}, {"step_s", step_s},                    {"confirm", confirm},
          {"refractory_s", refractory_s}, {"slack_s", slack_s}, {"model", model}, {"knn_k", knn_k},
          {"knn_samples", knn_samples}};
}

AnnotatedStream annotated_stream(const playback::Recording& rec, const FeatureOptions& features, bool require) {
  auto annotations = playback::annotations_of(rec);
  if (annotations.empty() && require)
    throw ModelError(rec.source + ": no annotations (a " +
                     std::filesystem::path(rec.source).stem().string() +
                     ".annotations.csv beside it, MSRC-12's .tagstream, or per-frame labels)");
  AnnotatedStream s;
  s.source = rec.source;
  const auto it = rec.metadata.find("subject");
  s.subject = it != rec.metadata.end() ? it->second : std::filesystem::path(rec.source).stem().string();
  for (const auto& f : rec.frames) s.stamps.push_back(f.stamp_ns);
  s.x = recording_features(rec, features).x;
  s.annotations = std::move(annotations);
  return s;
}

std::vector<double> parse_near_misses(const std::string& text) {
  std::vector<double> out;
  if (text == "none") return out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    std::size_t used = 0;
    double d = 0;
    try {
      d = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !(d >= -5.0 && d <= 5.0))
      throw std::invalid_argument("'" + item + "' is not a number of seconds in [-5, 5]");
    out.push_back(d);
  }
  return out;
}

ClassMap stream_class_map(const std::vector<AnnotatedStream>& streams) {
  std::set<std::string> labels;
  for (const auto& s : streams)
    for (const auto& a : s.annotations) labels.insert(a.label);
  ClassMap m;
  for (const auto& l : labels) {
    m.classes.push_back(l);
    m.action_class[l] = l;
  }
  m.garbage = "none";
  m.classes.push_back(m.garbage);
  m.action_class[m.garbage] = m.garbage;
  return m;
}

std::vector<Clip> stream_windows(const AnnotatedStream& s, const ClassMap& map, const StreamSpotOptions& o) {
  std::vector<Clip> clips;
  if (s.stamps.empty()) return clips;
  const auto add = [&](std::int64_t t, const std::string& action) {
    std::size_t end = 0;
    if (!frame_at(s, t, end) || s.stamps[end] - s.stamps.front() < ns(0.5 * o.window_s)) return;
    Clip c;
    c.source = s.source;
    c.subject = s.subject;
    c.action = action;
    c.label = map.label_of(action).value_or(-1);
    c.x = window_at(s, end, o.window_s);
    if (c.x.rows() >= 3) clips.push_back(std::move(c));
  };
  for (const auto& a : s.annotations)  // an action point, or a range's end: the gesture is complete there
    for (double d : o.positive_offsets_s) add(a.end_ns + ns(d), a.label);
  for (auto t = s.stamps.front() + ns(o.window_s); t <= s.stamps.back(); t += ns(o.negative_step_s)) {
    bool near = false;
    for (const auto& a : s.annotations) near = near || (t > a.start_ns - ns(o.negative_gap_s) && t < a.end_ns + ns(o.negative_gap_s));
    if (!near) add(t, map.garbage);
  }
  for (const auto& a : s.annotations)
    for (double d : o.near_negative_offsets_s) {
      const auto t = a.end_ns + ns(d);
      bool other = false;  // another gesture's action point (or range) this close: not garbage
      for (const auto& b : s.annotations) other = other || (&b != &a && t > b.start_ns - ns(kNearOther) && t < b.end_ns + ns(kNearOther));
      if (!other) add(t, map.garbage);
    }
  return clips;
}

WindowKnn::WindowKnn(const std::vector<Clip>& clips, const ClassMap& map, int k, int samples)
    : labels_(map.classes), garbage_(map.garbage_index()), k_(k), samples_(samples) {
  std::vector<const Clip*> use;
  for (const auto& c : clips)
    if (c.label >= 0 && c.x.rows() > 0) use.push_back(&c);
  if (use.empty()) throw ModelError("knn: no labelled training windows");
  const auto dim = static_cast<Eigen::Index>(use.front()->x.cols()) * samples_;
  Eigen::MatrixXd raw(dim, static_cast<Eigen::Index>(use.size()));
  mean_ = Eigen::VectorXd::Zero(dim);
  scale_ = Eigen::VectorXd::Ones(dim);
  for (std::size_t i = 0; i < use.size(); ++i) {
    raw.col(static_cast<Eigen::Index>(i)) = vec(use[i]->x);
    label_.push_back(use[i]->label);
  }
  mean_ = raw.rowwise().mean();
  const Eigen::MatrixXd centred = raw.colwise() - mean_;
  scale_ = (centred.array().square().rowwise().sum() / static_cast<double>(use.size())).sqrt().max(1e-6).matrix();
  train_ = centred.array().colwise() / scale_.array();
}

Eigen::VectorXd WindowKnn::vec(const Sequence& x) const {  // `samples_` rows, evenly over the window, stacked
  Eigen::VectorXd v(x.cols() * samples_);
  for (int i = 0; i < samples_; ++i) {
    const double at = samples_ == 1 ? 0.0 : static_cast<double>(i) * static_cast<double>(x.rows() - 1) / (samples_ - 1);
    const auto a = static_cast<Eigen::Index>(std::floor(at));
    const auto b = std::min<Eigen::Index>(a + 1, x.rows() - 1);
    const double u = at - static_cast<double>(a);
    v.segment(i * x.cols(), x.cols()) = ((1 - u) * x.row(a) + u * x.row(b)).transpose();
  }
  return v;
}

Decision WindowKnn::classify(const Sequence& x) const {
  const Eigen::VectorXd q = ((vec(x) - mean_).array() / scale_.array()).matrix();
  const Eigen::VectorXd d2 = (train_.colwise() - q).colwise().squaredNorm().transpose();
  std::vector<Eigen::Index> idx(static_cast<std::size_t>(d2.size()));
  for (Eigen::Index i = 0; i < d2.size(); ++i) idx[static_cast<std::size_t>(i)] = i;
  const auto k = std::min<std::size_t>(static_cast<std::size_t>(k_), idx.size());
  std::partial_sort(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(k), idx.end(),
                    [&](Eigen::Index a, Eigen::Index b) { return d2(a) < d2(b); });
  Decision d;
  d.scores.assign(labels_.size(), 0.0);
  for (std::size_t i = 0; i < k; ++i) d.scores[static_cast<std::size_t>(label_[static_cast<std::size_t>(idx[i])])] += 1.0;
  d.label = static_cast<int>(std::max_element(d.scores.begin(), d.scores.end()) - d.scores.begin());
  auto sorted = d.scores;
  std::sort(sorted.rbegin(), sorted.rend());
  d.margin = sorted.size() > 1 ? sorted[0] - sorted[1] : sorted[0];
  return d;
}

nlohmann::json WindowKnn::to_json() const {
  const auto matrix = [](const Eigen::MatrixXd& m) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) rows.push_back(std::vector<double>(m.col(c).data(), m.col(c).data() + m.rows()));
    return rows;
  };
  return {{"labels", labels_},
          {"garbage", garbage_},
          {"k", k_},
          {"samples", samples_},
          {"mean", std::vector<double>(mean_.data(), mean_.data() + mean_.size())},
          {"scale", std::vector<double>(scale_.data(), scale_.data() + scale_.size())},
          {"windows", matrix(train_)},
          {"window_labels", label_}};
}

WindowKnn WindowKnn::from_json(const nlohmann::json& j) {
  WindowKnn w;
  try {
    w.labels_ = j.at("labels").get<std::vector<std::string>>();
    w.garbage_ = j.at("garbage").get<int>();
    w.k_ = j.at("k").get<int>();
    w.samples_ = j.at("samples").get<int>();
    const auto mean = j.at("mean").get<std::vector<double>>();
    const auto scale = j.at("scale").get<std::vector<double>>();
    w.mean_ = Eigen::Map<const Eigen::VectorXd>(mean.data(), static_cast<Eigen::Index>(mean.size()));
    w.scale_ = Eigen::Map<const Eigen::VectorXd>(scale.data(), static_cast<Eigen::Index>(scale.size()));
    const auto& windows = j.at("windows");
    w.label_ = j.at("window_labels").get<std::vector<int>>();
    if (w.scale_.size() != w.mean_.size() || windows.size() != w.label_.size() || windows.empty() || w.k_ < 1 ||
        w.samples_ < 1 || w.mean_.size() % w.samples_ != 0)
      throw ModelError("knn: sizes do not agree");
    w.train_.resize(w.mean_.size(), static_cast<Eigen::Index>(windows.size()));
    for (std::size_t c = 0; c < windows.size(); ++c) {
      const auto v = windows[c].get<std::vector<double>>();
      if (static_cast<Eigen::Index>(v.size()) != w.mean_.size()) throw ModelError("knn: window " + std::to_string(c) + " has the wrong size");
      w.train_.col(static_cast<Eigen::Index>(c)) = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
    }
    for (int l : w.label_)
      if (l < 0 || l >= static_cast<int>(w.labels_.size())) throw ModelError("knn: a window label out of range");
  } catch (const nlohmann::json::exception& e) {
    throw ModelError(std::string("knn: ") + e.what());
  }
  return w;
}

namespace {
template <class Model>
std::vector<SpottedEvent> spot_with(const Model& c, const AnnotatedStream& s, const StreamSpotOptions& o) {
  std::vector<SpottedEvent> events;
  if (s.stamps.empty()) return events;
  int last = -1, run = 0;
  std::map<int, std::int64_t> quiet_until;
  for (auto t = s.stamps.front() + ns(o.window_s); t <= s.stamps.back(); t += ns(o.step_s)) {
    std::size_t end = 0;
    if (!frame_at(s, t, end)) continue;
    const auto x = window_at(s, end, o.window_s);
    if (x.rows() < 3) continue;
    const auto d = c.classify(x);
    const bool gesture = !d.rejected && d.label != c.garbage_index();
    run = gesture && d.label == last ? run + 1 : gesture ? 1 : 0;
    last = gesture ? d.label : -1;
    if (!gesture || run < o.confirm) continue;
    const auto now = s.stamps[end];
    if (now < quiet_until[d.label]) continue;
    quiet_until[d.label] = now + ns(o.refractory_s);
    SpottedEvent e;
    e.label = c.labels()[static_cast<std::size_t>(d.label)];
    e.start_ns = now - ns(o.window_s);
    e.end_ns = now;
    e.log_likelihood = d.scores[static_cast<std::size_t>(d.label)];
    e.confidence = 1.0 - std::exp(-d.margin);
    events.push_back(e);
  }
  return events;
}
}  // namespace

std::vector<SpottedEvent> spot_stream(const Classifier& c, const AnnotatedStream& s, const StreamSpotOptions& o) {
  return spot_with(c, s, o);
}
std::vector<SpottedEvent> spot_stream(const WindowKnn& c, const AnnotatedStream& s, const StreamSpotOptions& o) {
  return spot_with(c, s, o);
}

std::vector<TruthGesture> stream_truth(const AnnotatedStream& s) {
  std::vector<TruthGesture> t;
  for (const auto& a : s.annotations) t.push_back({a.label, a.start_ns, a.end_ns});
  return t;
}

nlohmann::json StreamSpotting::to_json() const {
  nlohmann::json per = nlohmann::json::array();
  for (const auto& r : per_class) per.push_back(gesture::to_json(r));
  return {{"classes", classes},          {"per_class", per},  {"macro_f1", macro_f1},
          {"median_latency_s", median_latency_s}, {"streams", streams}, {"training_windows", windows},
          {"subjects", subjects}};
}

StreamSpotter StreamSpotter::train(const std::vector<AnnotatedStream>& streams, const ClassifierOptions& c,
                                   const StreamSpotOptions& o) {
  const auto map = stream_class_map(streams);
  StreamSpotter s;
  s.features_ = c.features.set;
  s.options_ = o;
  for (const auto& k : map.classes)
    if (k != map.garbage) s.classes_.push_back(k);
  std::vector<Clip> windows;
  for (const auto& st : streams) {
    auto w = stream_windows(st, map, o);
    windows.insert(windows.end(), std::make_move_iterator(w.begin()), std::make_move_iterator(w.end()));
  }
  s.windows_ = windows.size();
  if (o.model == "knn") s.knn_.emplace(windows, map, o.knn_k, o.knn_samples);
  else s.hmm_ = Classifier::train(windows, map, c);
  return s;
}

std::vector<SpottedEvent> StreamSpotter::spot(const AnnotatedStream& st) const {
  return knn_ ? spot_stream(*knn_, st, options_) : spot_stream(*hmm_, st, options_);
}

const std::vector<std::string>& StreamSpotter::classes() const { return classes_; }

void StreamSpotter::save(const std::string& path) const {
  nlohmann::json j{{"format", "skelgraph-stream-spotter"},
                   {"version", 1},
                   {"features", feature_set_name(features_)},
                   {"spotting", options_.to_json()},
                   {"classes", classes_},
                   {"training_windows", windows_}};
  if (knn_) j["knn"] = knn_->to_json();
  else j["hmm"] = hmm_->to_json();
  std::ofstream f(path);
  if (!f) throw ModelError("cannot write " + path);
  f << j.dump() << '\n';
  if (!f) throw ModelError("cannot write " + path);
}

bool StreamSpotter::is_stream_spotter(const std::string& path) {
  try {
    const auto j = read_model_json(path);
    return j.is_object() && j.value("format", "") == "skelgraph-stream-spotter";
  } catch (const ModelError&) {
    return false;  // not a readable JSON file: whoever loads it says why
  }
}

StreamSpotter StreamSpotter::load(const std::string& path) {
  const auto j = read_model_json(path);
  StreamSpotter s;
  try {
    if (j.value("format", "") != "skelgraph-stream-spotter" || j.value("version", 0) != 1)
      throw ModelError("not a skelgraph-stream-spotter version 1");
    const auto set = feature_set_from_name(j.at("features").get<std::string>());
    if (!set) throw ModelError("unknown feature set '" + j.at("features").get<std::string>() + "'");
    s.features_ = *set;
    const auto& o = j.at("spotting");
    s.options_.window_s = o.at("window_s").get<double>();
    s.options_.positive_offsets_s = o.at("positive_offsets_s").get<std::vector<double>>();
    s.options_.negative_gap_s = o.at("negative_gap_s").get<double>();
    s.options_.negative_step_s = o.at("negative_step_s").get<double>();
    // Spotters saved before near misses were trained without them.
    s.options_.near_negative_offsets_s = o.value("near_negative_offsets_s", std::vector<double>{});
    s.options_.step_s = o.at("step_s").get<double>();
    s.options_.confirm = o.at("confirm").get<int>();
    s.options_.refractory_s = o.at("refractory_s").get<double>();
    s.options_.slack_s = o.at("slack_s").get<double>();
    s.options_.model = o.at("model").get<std::string>();
    s.options_.knn_k = o.at("knn_k").get<int>();
    s.options_.knn_samples = o.at("knn_samples").get<int>();
    s.classes_ = j.at("classes").get<std::vector<std::string>>();
    s.windows_ = j.at("training_windows").get<std::size_t>();
    if (j.contains("knn")) s.knn_ = WindowKnn::from_json(j.at("knn"));
    else if (j.contains("hmm")) s.hmm_ = Classifier::from_json(j.at("hmm"));
    else throw ModelError("neither 'knn' nor 'hmm'");
    if (s.options_.step_s <= 0 || s.options_.window_s <= 0) throw ModelError("spotting: window_s and step_s must be > 0");
  } catch (const nlohmann::json::exception& e) {
    throw ModelError(path + ": " + e.what());
  } catch (const ModelError& e) {
    throw ModelError(path + ": " + e.what());
  }
  return s;
}

StreamSpotting cross_validate_streams(const std::vector<AnnotatedStream>& streams, const ClassifierOptions& c,
                                      const StreamSpotOptions& o, const std::function<void(int, int)>& progress) {
  const auto map = stream_class_map(streams);
  StreamSpotting out;
  for (const auto& k : map.classes)
    if (k != map.garbage) out.classes.push_back(k);
  std::set<std::string> subjects;
  for (const auto& s : streams) subjects.insert(s.subject);
  out.subjects.assign(subjects.begin(), subjects.end());
  if (subjects.size() < 2) throw ModelError("leave-subject-out needs streams of at least two subjects");
  std::vector<std::vector<Clip>> windows;
  for (const auto& s : streams) windows.push_back(stream_windows(s, map, o));
  std::map<std::string, std::vector<SpottingReport>> reports;
  int done = 0;
  for (const auto& held : out.subjects) {
    std::vector<Clip> train;
    for (std::size_t i = 0; i < streams.size(); ++i)
      if (streams[i].subject != held) train.insert(train.end(), windows[i].begin(), windows[i].end());
    out.windows += train.size();
    std::optional<Classifier> hmm;
    std::optional<WindowKnn> knn;
    if (o.model == "knn") knn.emplace(train, map, o.knn_k, o.knn_samples);
    else hmm = Classifier::train(train, map, c);
    for (const auto& s : streams) {
      if (s.subject != held) continue;
      const auto events = knn ? spot_stream(*knn, s, o) : spot_stream(*hmm, s, o);
      const auto truth = stream_truth(s);
      for (const auto& k : out.classes) reports[k].push_back(score_spotting(events, truth, k, o.slack_s));
      ++out.streams;
    }
    if (progress) progress(++done, static_cast<int>(out.subjects.size()));
  }
  std::vector<double> latencies;
  for (const auto& k : out.classes) {
    out.per_class.push_back(combine(reports[k]));
    out.macro_f1 += out.per_class.back().f1 / static_cast<double>(out.classes.size());
    latencies.insert(latencies.end(), out.per_class.back().latency_s.begin(), out.per_class.back().latency_s.end());
  }
  out.median_latency_s = stats::median(latencies);
  return out;
}

}  // namespace skelgraph::gesture
