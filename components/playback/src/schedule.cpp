#include "skelgraph/playback/schedule.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace skelgraph::playback {

PlaybackSchedule::PlaybackSchedule(std::vector<skeleton::Skeleton> frames, Options options)
    : frames_(std::move(frames)), options_(options) {
  if (options_.rate < 0.0 || !std::isfinite(options_.rate)) throw std::invalid_argument("rate must be >= 0");
  std::stable_sort(frames_.begin(), frames_.end(),
                   [](const skeleton::Skeleton& a, const skeleton::Skeleton& b) { return a.stamp_ns < b.stamp_ns; });
  if (frames_.size() >= 2) {
    // A loop lasts the recording plus one median frame period, so the first
    // frame of the next loop does not land on the last one of this loop.
    std::vector<std::int64_t> steps;
    for (std::size_t i = 1; i < frames_.size(); ++i) {
      if (frames_[i].stamp_ns > frames_[i - 1].stamp_ns) steps.push_back(frames_[i].stamp_ns - frames_[i - 1].stamp_ns);
    }
    std::int64_t period = 33'333'333;
    if (!steps.empty()) {
      std::nth_element(steps.begin(), steps.begin() + static_cast<long>(steps.size() / 2), steps.end());
      period = steps[steps.size() / 2];
    }
    duration_ns_ = frames_.back().stamp_ns - frames_.front().stamp_ns + period;
  } else {
    duration_ns_ = 33'333'333;
  }
}

std::vector<skeleton::Skeleton> PlaybackSchedule::due(std::int64_t elapsed_ns, std::int64_t start_stamp_ns) {
  std::vector<skeleton::Skeleton> out;
  if (frames_.empty()) return out;
  const auto first = frames_.front().stamp_ns;
  while (true) {
    if (next_ >= frames_.size()) {
      if (!options_.loop) break;
      next_ = 0;
      ++loops_;
    }
    // Recorded offset of the next frame, including completed loops.
    const std::int64_t offset = frames_[next_].stamp_ns - first + static_cast<std::int64_t>(loops_) * duration_ns_;
    std::int64_t at = 0;  // playback time it is due
    if (options_.rate > 0.0) {
      at = static_cast<std::int64_t>(std::llround(static_cast<double>(offset) / options_.rate));
      if (at > elapsed_ns) break;
    } else if (out.size() >= options_.max_batch) {
      break;
    }
    auto s = frames_[next_];
    if (options_.restamp) s.stamp_ns = start_stamp_ns + (options_.rate > 0.0 ? at : elapsed_ns);
    out.push_back(std::move(s));
    ++next_;
    ++published_;
  }
  return out;
}

}  // namespace skelgraph::playback
