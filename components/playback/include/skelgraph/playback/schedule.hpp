#pragma once
// When each recorded frame is due during playback: recorded time scaled by a
// rate (0: as fast as possible), looping if asked, re-stamped to the playback
// clock so downstream components see a live stream. DDS-free; time passed in.

#include <cstdint>
#include <vector>

#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::playback {

class PlaybackSchedule {
 public:
  struct Options {
    double rate = 1.0;          // 2.0 plays twice as fast; 0 as fast as possible
    bool loop = false;
    bool restamp = true;        // stamps become start_stamp_ns + (scaled) recorded offset
    std::size_t max_batch = 256;  // frames per call when rate is 0
  };

  // `frames` in any order; they are played in stamp order.
  PlaybackSchedule(std::vector<skeleton::Skeleton> frames, Options options);

  // Frames due `elapsed_ns` after the start; `start_stamp_ns` is the wall-clock start.
  std::vector<skeleton::Skeleton> due(std::int64_t elapsed_ns, std::int64_t start_stamp_ns);

  bool finished() const { return !options_.loop && next_ >= frames_.size(); }
  std::uint64_t published() const { return published_; }
  std::uint32_t loops_completed() const { return loops_; }
  std::size_t size() const { return frames_.size(); }
  std::int64_t duration_ns() const { return duration_ns_; }  // first to last stamp + one frame period

 private:
  std::vector<skeleton::Skeleton> frames_;
  Options options_;
  std::size_t next_ = 0;
  std::uint32_t loops_ = 0;
  std::uint64_t published_ = 0;
  std::int64_t duration_ns_ = 0;
};

}  // namespace skelgraph::playback
