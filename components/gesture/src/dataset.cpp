#include "skelgraph/gesture/dataset.hpp"

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "skelgraph/skeleton/stats.hpp"

namespace skelgraph::gesture {

std::vector<std::string> expand_paths(const std::vector<std::string>& paths) {
  std::vector<std::string> out;
  for (const auto& p : paths) {
    if (!std::filesystem::is_directory(p)) {
      out.push_back(p);
      continue;
    }
    std::vector<std::string> in_dir;
    for (const auto& e : std::filesystem::directory_iterator(p))
      if (e.is_regular_file() && e.path().extension() == ".csv") in_dir.push_back(e.path().string());
    if (in_dir.empty()) throw ModelError(p + ": no .csv files in this directory");
    std::sort(in_dir.begin(), in_dir.end());
    out.insert(out.end(), in_dir.begin(), in_dir.end());
  }
  return out;
}

std::vector<Wrists> wrists_of(const playback::Recording& recording) {
  const auto left = recording.extra_joints.find("left_wrist"), right = recording.extra_joints.find("right_wrist");
  if (left == recording.extra_joints.end() || right == recording.extra_joints.end()) return {};
  std::vector<Wrists> wrists(recording.frames.size());
  for (std::size_t t = 0; t < wrists.size() && t < left->second.size() && t < right->second.size(); ++t)
    wrists[t] = {left->second[t], right->second[t]};
  return wrists;
}

Features recording_features(const playback::Recording& recording, const FeatureOptions& options) {
  if (!needs_wrists(options.set)) return features_of(recording.frames, options);
  const auto wrists = wrists_of(recording);
  if (wrists.empty() && !recording.frames.empty())
    throw ModelError(recording.source + ": the '" + feature_set_name(options.set) + "' features need wrist joints; this " +
                     recording.format + " recording has none (Kinect v1/v2 formats do)");
  return features_of(recording.frames, options, &wrists);
}

Sequence clip_features(const playback::Recording& recording, const DatasetOptions& o) {
  Sequence x = recording_features(recording, o.features).x;
  if (!o.trim) return x;
  const Span s = motion_span(x, o.features.set);
  return x.middleRows(s.begin, s.end - s.begin);
}

namespace {
Clip load_clip(const std::string& file, const ClassMap& map, const DatasetOptions& o, LoadReport* report) {
  const auto rec = playback::read_recording(o.format, file, o.read);
  if (report && rec.report.skipped > 0) report->skipped.push_back(playback::skipped_summary(rec));
  Clip c;
  c.source = file;
  const auto meta = [&](const char* k) {
    const auto it = rec.metadata.find(k);
    return it == rec.metadata.end() ? std::string() : it->second;
  };
  c.action = meta("action");
  if (c.action.empty()) c.action = meta("gesture");
  if (c.action.empty())
    throw playback::DataError(file, 1, "no action label (expected 'action' or 'gesture' metadata, or a format's action column)");
  c.subject = meta("subject");
  if (c.subject.empty()) c.subject = std::filesystem::path(file).stem().string();
  if (rec.frames.size() < 2)
    throw playback::DataError(file, rec.report.last_line, "one skeleton frame only: a clip needs at least 2");
  c.label = map.label_of(c.action).value_or(-1);
  c.x = clip_features(rec, o);
  // Arm length: shoulder-elbow-hand of either arm, median over the frames where all three are seen.
  std::vector<double> arms;
  using J = skeleton::JointId;
  for (const auto& f : rec.frames)
    for (const auto& [s, e, h] : {std::tuple{J::LeftShoulder, J::LeftElbow, J::LeftHand}, std::tuple{J::RightShoulder, J::RightElbow, J::RightHand}})
      if (f[s].confidence > 0 && f[e].confidence > 0 && f[h].confidence > 0)
        arms.push_back((f[s].position - f[e].position).norm() + (f[e].position - f[h].position).norm());
  if (!arms.empty()) c.arm_length_m = stats::median(arms);
  return c;
}
}  // namespace

std::vector<Clip> load_clips(const std::vector<std::string>& paths, const ClassMap& map, const DatasetOptions& o,
                             LoadReport* report) {
  std::vector<Clip> clips;
  for (const auto& file : expand_paths(paths)) {
    if (!report) {
      clips.push_back(load_clip(file, map, o, nullptr));
      continue;
    }
    try {
      clips.push_back(load_clip(file, map, o, report));
    } catch (const playback::DataError& e) {
      report->bad.push_back(e.what());
    } catch (const ModelError& e) {
      report->bad.push_back(playback::printable(e.what()));
    }
  }
  return clips;
}

bool inputs_have_wrists(const std::vector<std::string>& paths, const DatasetOptions& o) {
  for (const auto& file : expand_paths(paths)) {
    try {
      const auto rec = playback::read_recording(o.format, file, o.read);
      if (rec.frames.empty()) continue;
      return !wrists_of(rec).empty();
    } catch (const playback::DataError&) {
      // a bad file: the next one decides, and the load reports this one
    }
  }
  return false;
}

void ModelConfiguration::apply(ClassifierOptions& c) const {
  c.features.set = features;
  c.hmm.states = states;
  c.hmm.mixtures = mixtures;
  c.hmm.covariance = covariance;
  c.hmm.init = init;
  c.hmm.restarts = restarts;
}

std::string ModelConfiguration::describe() const {
  return std::string(feature_set_name(features)) + " features, " + std::to_string(states) + " states, " + std::to_string(mixtures) +
         " mixtures, " + (covariance == Covariance::Full ? "full" : "diag") + " covariance, " + init_name(init) + " x " +
         std::to_string(restarts);
}

ModelConfiguration best_configuration(const std::string& class_set, bool wrists) {
  ModelConfiguration m;  // thesis8, 7 states, full: the best without wrists
  if (!wrists) {
    m.measured = "two-class 95.6 % leave-subject-out, the best measured without wrists";
    return m;
  }
  if (class_set == "five-class") {
    m.features = FeatureSet::Arm;
    m.states = 3;
    m.mixtures = 1;
    m.covariance = Covariance::Diagonal;
    m.init = Init::KMeans;
    m.restarts = 16;
    m.measured = "five-class 92.0 % leave-subject-out";
    return m;
  }
  m.features = FeatureSet::Hands;
  m.states = 3;
  m.mixtures = 2;
  m.covariance = Covariance::Diagonal;
  m.measured = class_set == "robot"       ? "robot 81.2 % leave-subject-out"
               : class_set == "two-class" ? "two-class 98.8 % leave-subject-out, point F1 0.91"
                                          : "two-class's best (98.8 %); not measured for this class set";
  return m;
}

}  // namespace skelgraph::gesture
