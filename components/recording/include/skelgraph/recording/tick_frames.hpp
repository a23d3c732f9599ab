#pragma once
// Frames associated with sync ticks, on the master's timeline: for every tick,
// the latest frame of every stream (topic, sensor, person) received at or
// before the tick and not older than a maximum age. What `bag merge` stores
// on skelgraph/sync/tick_frames, so a merged recording says which frames of
// which hosts belong together (the thesis saved one frame per client per 'A').

#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "skelgraph/msg/messages.hpp"

namespace skelgraph::recording {

inline constexpr const char* kTickFramesTopic = "skelgraph/sync/tick_frames";

class TickAssociator {
 public:
  // Frames older than max_age_ns at a tick are not associated with it (a stream
  // that stopped does not stay attached to every later tick).
  explicit TickAssociator(std::int64_t max_age_ns) : max_age_ns_(max_age_ns) {}

  // Feed in order of (corrected) log time; ticks and frames interleaved.
  // A tick's frames are those fed before it. Returns the tick's association.
  msg::TickFrames tick(std::uint32_t session_id, std::uint32_t tick, std::int64_t master_stamp_ns,
                       std::int64_t log_time_ns);
  void frame(const msg::FrameRef& f);

 private:
  std::int64_t max_age_ns_;
  std::map<std::tuple<std::string, std::string, std::uint32_t>, msg::FrameRef> latest_;  // topic, sensor, person
};

}  // namespace skelgraph::recording
