#include "skelgraph/sync/sync_master_core.hpp"

#include <algorithm>
#include <stdexcept>

namespace skelgraph::sync {

SyncMasterCore::SyncMasterCore(Config config) : config_(config) {
  if (config_.tick_period_ns <= 0) throw std::invalid_argument("tick period must be positive");
  if (config_.session_duration_ns < 0) throw std::invalid_argument("session duration must not be negative");
}

std::vector<SyncEvent> SyncMasterCore::start(const std::string& label, std::int64_t mono_ns, std::int64_t stamp_ns,
                                             const std::string& request_id) {
  std::vector<SyncEvent> out = stop(stamp_ns, request_id);
  // Session ids are the start second (unique across master restarts), or the
  // previous id + 1 when two sessions start within a second.
  const auto from_clock = static_cast<std::uint32_t>(stamp_ns / 1'000'000'000LL);
  session_id_ = std::max(from_clock, session_id_ + 1);
  label_ = label;
  running_ = true;
  start_mono_ns_ = mono_ns;
  last_tick_ = 0;
  ++sessions_;
  out.push_back({SyncEvent::Kind::Start, session_id_, label_, 0, stamp_ns, request_id});
  return out;
}

std::vector<SyncEvent> SyncMasterCore::stop(std::int64_t stamp_ns, const std::string& request_id) {
  if (!running_) return {};
  running_ = false;
  return {{SyncEvent::Kind::Stop, session_id_, label_, last_tick_, stamp_ns, request_id}};
}

std::vector<SyncEvent> SyncMasterCore::advance(std::int64_t mono_ns, std::int64_t stamp_ns) {
  std::vector<SyncEvent> out;
  if (!running_) return out;
  const std::int64_t elapsed = mono_ns - start_mono_ns_;
  std::int64_t until = elapsed;
  const bool ends = config_.session_duration_ns > 0 && elapsed >= config_.session_duration_ns;
  if (ends) until = config_.session_duration_ns;
  if (until > 0) {
    const auto due = static_cast<std::uint64_t>(until / config_.tick_period_ns);
    if (due > last_tick_ + config_.max_catch_up) {
      skipped_ += due - last_tick_ - config_.max_catch_up;
      last_tick_ = due - config_.max_catch_up;
    }
    for (std::uint64_t k = last_tick_ + 1; k <= due; ++k) {
      out.push_back({SyncEvent::Kind::Tick, session_id_, label_, k, stamp_ns, {}});
    }
    last_tick_ = std::max(last_tick_, due);
  }
  if (ends) {
    auto s = stop(stamp_ns);
    out.insert(out.end(), s.begin(), s.end());
  }
  return out;
}

}  // namespace skelgraph::sync
