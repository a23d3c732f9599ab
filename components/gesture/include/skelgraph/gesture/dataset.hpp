#pragma once
// Labelled clips for training and cross-validation, read from recorded data
// sets (playback readers: Kinder-Gator, generic CSV, ...). No DDS.

#include <string>
#include <vector>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/playback/readers.hpp"

namespace skelgraph::gesture {

struct DatasetOptions {
  playback::Format format = playback::Format::KinderGator;
  FeatureOptions features;
  bool trim = true;  // keep only the motion_span of each clip (the idle start and end are alike in every class)
  playback::ReadOptions read;  // a bad line: stop (the file is bad) or skip it
};

// The recording's wrists, one per frame (from extra_joints); empty when it has none.
std::vector<Wrists> wrists_of(const playback::Recording& recording);

// A recording's features (untrimmed), with its wrists for the sets that use
// them; a ModelError naming the file when such a set meets a recording without.
Features recording_features(const playback::Recording& recording, const FeatureOptions& options);

// A recording's features as the classifier sees them (trimmed when asked).
Sequence clip_features(const playback::Recording& recording, const DatasetOptions& options);

// Every file (a directory: its *.csv files, sorted) becomes one clip: the
// action from the recording's "action" (or "gesture") metadata, the subject
// from "subject" (else the file name), the label from the class map (-1 if
// the action is in no class). Throws playback::DataError / ModelError naming
// the file; with a report, a bad file's message goes there instead and the
// other files are still read.
struct LoadReport {
  std::vector<std::string> bad;      // a file each that was left out: "FILE:LINE: what"
  std::vector<std::string> skipped;  // a file each whose bad lines were skipped (ReadOptions::OnError::Skip)
};
std::vector<Clip> load_clips(const std::vector<std::string>& paths, const ClassMap& map, const DatasetOptions& options,
                             LoadReport* report = nullptr);

// The files `paths` name: files as given, directories expanded to their *.csv files.
std::vector<std::string> expand_paths(const std::vector<std::string>& paths);

// Whether the inputs carry wrist joints (what the hands and arm features
// need): the first file that reads decides; false when none reads.
bool inputs_have_wrists(const std::vector<std::string>& paths, const DatasetOptions& options);

// The best configuration measured for a class set (leave-subject-out on
// Kinder-Gator's ten adults), which `gesture train` and `gesture cv` use
// when no model option is given. With wrists: two-class hands 3 states 2
// mixtures diagonal (98.8 %), five-class arm 3/1 diagonal from k-means with
// 16 restarts (92.0 %), robot as two-class (81.2 %), a class file as
// two-class (not measured for it); without wrists thesis8 7 states full
// (two-class 95.6 %, the best measured without them).
struct ModelConfiguration {
  FeatureSet features = FeatureSet::Thesis8;
  int states = 7, mixtures = 1;
  Covariance covariance = Covariance::Full;
  Init init = Init::Segments;
  int restarts = 1;
  std::string measured;  // what it reached, for the user
  void apply(ClassifierOptions& c) const;
  std::string describe() const;  // "hands features, 3 states, 2 mixtures, diag covariance, segments x 1"
};
ModelConfiguration best_configuration(const std::string& class_set, bool wrists);

}  // namespace skelgraph::gesture
