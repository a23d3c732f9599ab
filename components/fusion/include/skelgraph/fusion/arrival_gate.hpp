#pragma once
// When to fuse on arrival (the fusion component's trigger `arrival`): as soon
// as every live sensor has delivered a whole frame since the last fusion, or
// a bounded wait after the first such frame has passed. DDS-free, time passed in.
//
// A frame is whole when its SensorFrame (the source's per-frame heartbeat,
// published after the frame's skeletons, with their count) and that many raw
// skeletons of its frame number have both arrived, in either order (they
// travel on different topics). A sensor that never sent a SensorFrame (e.g. a
// data-set player) completes a frame with each skeleton of a new frame number.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace skelgraph::fusion {

class ArrivalGate {
 public:
  explicit ArrivalGate(std::int64_t max_wait_ns) : max_wait_ns_(max_wait_ns) {}

  void frame(const std::string& sensor, std::uint64_t frame_number, std::uint32_t people, std::int64_t t_ns);
  void skeleton(const std::string& sensor, std::uint64_t frame_number, std::int64_t t_ns);

  // Fuse now? `live`: the sensors that count (heard lately, with a pose).
  // AllArrived when each has a whole frame newer than the last fusion;
  // WaitedOut when some have and the wait since the first reached max_wait_ns.
  enum class Ready { NotYet, AllArrived, WaitedOut };
  Ready ready(const std::vector<std::string>& live, std::int64_t now_ns) const;
  // When the bounded wait ends (a timer can fire then); empty if nothing new arrived.
  std::optional<std::int64_t> deadline() const;
  // A fusion ran (for the reason given): what arrived so far is used.
  void fused(Ready why);

  struct Counts {
    std::uint64_t whole_frames = 0;  // frames seen whole
    std::uint64_t all_arrived = 0;   // fusions because every live sensor delivered
    std::uint64_t waited_out = 0;    // fusions because the wait ran out
  };
  const Counts& counts() const { return counts_; }

 private:
  struct Sensor {
    bool announces = false;                           // sends SensorFrame
    std::map<std::uint64_t, std::uint32_t> received;  // skeletons per recent frame number
    std::map<std::uint64_t, std::uint32_t> expected;  // announced frames not yet whole: their skeleton count
    std::uint64_t last_whole = 0;                     // frame number of the newest whole frame
    std::uint64_t whole = 0, used = 0;                // whole frames so far; at the last fusion
  };
  void whole_frame(Sensor& s, std::uint64_t frame_number, std::int64_t t_ns);
  void check(Sensor& s, std::uint64_t frame_number, std::int64_t t_ns);

  std::int64_t max_wait_ns_;
  std::map<std::string, Sensor> sensors_;
  std::optional<std::int64_t> first_new_ns_;  // first whole frame since the last fusion
  Counts counts_;
};

}  // namespace skelgraph::fusion
