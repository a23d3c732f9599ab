#include "skelgraph/recording/tick_frames.hpp"

namespace skelgraph::recording {

void TickAssociator::frame(const msg::FrameRef& f) {
  latest_[{f.topic().to_string(), f.sensor_id().to_string(), f.person_id()}] = f;
}

msg::TickFrames TickAssociator::tick(std::uint32_t session_id, std::uint32_t tick, std::int64_t master_stamp_ns,
                                     std::int64_t log_time_ns) {
  msg::TickFrames out;
  out.session_id(session_id);
  out.tick(tick);
  out.master_stamp_ns(master_stamp_ns);
  for (auto it = latest_.begin(); it != latest_.end();) {
    if (log_time_ns - it->second.log_time_ns() > max_age_ns_) {
      it = latest_.erase(it);  // stale: it will not come back as "current"
      continue;
    }
    out.frames().push_back(it->second);
    ++it;
  }
  return out;
}

}  // namespace skelgraph::recording
