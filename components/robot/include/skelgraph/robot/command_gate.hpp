#pragma once
// Which commands the robot takes, beside what DDS Security's permissions
// allow (defence in depth, the `lan` profile has no permissions at all): one
// from a source it knows, stamped recently by the sender's clock. Pure, time
// passed in.

#include <cstdint>
#include <string>
#include <vector>

namespace skelgraph::robot {

struct CommandGate {
  std::vector<std::string> accept_from;  // sources (the commanding component's name); empty: any
  double max_age_s = 1.0;                // older (or this far in the future: a clock off) is refused
};

struct GateVerdict {
  bool ok = true;
  bool stale = false;   // refused for its stamp
  std::string reason;   // when refused: says the source and why
};

GateVerdict check_command(const CommandGate& gate, const std::string& source, std::int64_t stamp_ns, std::int64_t now_ns);

}  // namespace skelgraph::robot
