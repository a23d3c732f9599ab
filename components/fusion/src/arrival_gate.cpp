#include "skelgraph/fusion/arrival_gate.hpp"

#include <algorithm>

namespace skelgraph::fusion {

namespace {
constexpr std::size_t kKeep = 8;  // frame numbers remembered per sensor
template <class Map>
void trim(Map& m) {
  while (m.size() > kKeep) m.erase(m.begin());
}
}  // namespace

void ArrivalGate::whole_frame(Sensor& s, std::uint64_t frame_number, std::int64_t t_ns) {
  if (s.whole > 0 && frame_number <= s.last_whole) return;  // (late, or already counted)
  s.last_whole = frame_number;
  ++s.whole;
  ++counts_.whole_frames;
  if (!first_new_ns_) first_new_ns_ = t_ns;
}

void ArrivalGate::check(Sensor& s, std::uint64_t frame_number, std::int64_t t_ns) {
  const auto want = s.expected.find(frame_number);
  if (want == s.expected.end()) return;
  const auto got = s.received.find(frame_number);
  if ((got == s.received.end() ? 0u : got->second) < want->second) return;
  s.expected.erase(want);
  whole_frame(s, frame_number, t_ns);
}

void ArrivalGate::frame(const std::string& sensor, std::uint64_t frame_number, std::uint32_t people,
                        std::int64_t t_ns) {
  auto& s = sensors_[sensor];
  s.announces = true;
  s.expected[frame_number] = people;
  trim(s.expected);
  check(s, frame_number, t_ns);
}

void ArrivalGate::skeleton(const std::string& sensor, std::uint64_t frame_number, std::int64_t t_ns) {
  auto& s = sensors_[sensor];
  if (!s.announces) {
    whole_frame(s, frame_number, t_ns);
    return;
  }
  ++s.received[frame_number];
  trim(s.received);
  check(s, frame_number, t_ns);
}

ArrivalGate::Ready ArrivalGate::ready(const std::vector<std::string>& live, std::int64_t now_ns) const {
  if (!first_new_ns_) return Ready::NotYet;
  const bool all = !live.empty() && std::all_of(live.begin(), live.end(), [&](const std::string& id) {
    const auto it = sensors_.find(id);
    return it != sensors_.end() && it->second.whole > it->second.used;
  });
  if (all) return Ready::AllArrived;
  return now_ns - *first_new_ns_ >= max_wait_ns_ ? Ready::WaitedOut : Ready::NotYet;
}

std::optional<std::int64_t> ArrivalGate::deadline() const {
  if (!first_new_ns_) return std::nullopt;
  return *first_new_ns_ + max_wait_ns_;
}

void ArrivalGate::fused(Ready why) {
  if (why == Ready::AllArrived) ++counts_.all_arrived;
  if (why == Ready::WaitedOut) ++counts_.waited_out;
  for (auto& [id, s] : sensors_) s.used = s.whole;
  first_new_ns_.reset();
}

}  // namespace skelgraph::fusion
