#pragma once
// Spotting gestures in continuous streams made of real clips (`skelgraph
// gesture spot`): each subject's recordings played one after another (in
// file-name order: the order they were performed), with `gap_s` of the last
// frame held between them and, with `rest_s`, the arms lowered, held down and
// raised into the next clip; spotted by a model trained on the other
// subjects (leave-subject-out); truth: each clip's motion span, labelled by
// its class. DDS-free.

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/features.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/playback/readers.hpp"

namespace skelgraph::gesture {

struct ClipStreamOptions {
  playback::Format format = playback::Format::KinderGator;  // of the clips' source files
  playback::ReadOptions read;                               // ... and how they were read
  double gap_s = 0.0;   // the last frame of a clip held this long before the next
  double rest_s = 0.0;  // arms down and still this long between clips (0: none)
  SpotterOptions spot;
};

struct SubjectSpotting {
  std::string subject;
  std::size_t clips = 0;
  SpottingReport report;
  nlohmann::json spotted;          // the events: label, the clip it fell in ("rest" between), start/end s, confidence
  nlohmann::json clips_in_stream;  // each clip's place in the stream and its motion span
};

struct ClipSpotting {
  std::string label;  // the class spotted (the class map's first)
  std::vector<SubjectSpotting> subjects;
  SpottingReport combined;
};

// Throws std::invalid_argument with fewer than 2 subjects.
ClipSpotting spot_clips(const std::vector<Clip>& clips, const ClassMap& map, const ClassifierOptions& c,
                        const ClipStreamOptions& o, const std::function<void(int done, int total)>& progress = {});

// The same person with both arms hanging: elbows, wrists and hands straight
// below their shoulders, segment lengths kept.
std::pair<skeleton::Skeleton, Wrists> arms_down(const skeleton::Skeleton& s, const Wrists& w);

}  // namespace skelgraph::gesture
