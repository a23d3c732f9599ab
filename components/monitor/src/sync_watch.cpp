#include "skelgraph/monitor/sync_watch.hpp"

namespace skelgraph::monitor {

SyncWatch::Entry& SyncWatch::entry(std::uint32_t session_id, const std::string& label) {
  for (auto& e : entries_) {
    if (e.obs.session_id == session_id) return e;
  }
  entries_.push_back(Entry{});
  entries_.back().obs.session_id = session_id;
  entries_.back().obs.label = label;
  return entries_.back();
}

void SyncWatch::on_command(Kind kind, std::uint32_t session_id, const std::string& label, std::uint64_t tick,
                           std::int64_t master_stamp_ns, std::int64_t receive_ns) {
  auto& e = entry(session_id, label);
  switch (kind) {
    case Kind::Start: e.obs.saw_start = true; break;
    case Kind::Stop:
      e.obs.saw_stop = true;
      e.obs.stop_tick = tick;
      break;
    case Kind::Tick:
      if (e.obs.ticks == 0) {
        e.obs.first_tick = tick;
        e.first_stamp_ns = master_stamp_ns;
      } else if (tick > e.obs.last_tick + 1) {
        e.obs.missing_ticks += tick - e.obs.last_tick - 1;
      }
      if (tick > e.obs.last_tick) {
        e.obs.last_tick = tick;
        e.last_stamp_ns = master_stamp_ns;
      }
      ++e.obs.ticks;
      e.rate.add(receive_ns);
      break;
  }
}

std::vector<SessionObservation> SyncWatch::sessions() const {
  std::vector<SessionObservation> out;
  for (const auto& e : entries_) {
    out.push_back(e.obs);
    out.back().arrival = e.rate.summary();
    const auto span = e.last_stamp_ns - e.first_stamp_ns;
    if (e.obs.last_tick > e.obs.first_tick && span > 0) {
      out.back().master_rate_hz = static_cast<double>(e.obs.last_tick - e.obs.first_tick) / (static_cast<double>(span) * 1e-9);
    }
  }
  return out;
}

}  // namespace skelgraph::monitor
