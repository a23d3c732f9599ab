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
                           std::int64_t receive_ns) {
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
      } else if (tick > e.obs.last_tick + 1) {
        e.obs.missing_ticks += tick - e.obs.last_tick - 1;
      }
      e.obs.last_tick = tick > e.obs.last_tick ? tick : e.obs.last_tick;
      ++e.obs.ticks;
      e.rate.add(receive_ns);
      break;
  }
}

std::vector<SessionObservation> SyncWatch::sessions() const {
  std::vector<SessionObservation> out;
  for (const auto& e : entries_) {
    out.push_back(e.obs);
    out.back().tick_rate = e.rate.summary();
  }
  return out;
}

}  // namespace skelgraph::monitor
