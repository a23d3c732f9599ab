#include "skelgraph/robot/command_gate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skelgraph::robot {

GateVerdict check_command(const CommandGate& gate, const std::string& source, std::int64_t stamp_ns, std::int64_t now_ns) {
  GateVerdict v;
  const std::string who = source.empty() ? "(no source)" : "'" + source + "'";
  if (!gate.accept_from.empty() &&
      std::find(gate.accept_from.begin(), gate.accept_from.end(), source) == gate.accept_from.end()) {
    v.ok = false;
    v.reason = "a command from " + who + ", not a source it takes (accept_from)";
    return v;
  }
  const double age_s = static_cast<double>(now_ns - stamp_ns) * 1e-9;
  if (!(std::abs(age_s) <= gate.max_age_s)) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.3f", age_s);
    v.ok = false;
    v.stale = true;
    v.reason = "a command from " + who + " stamped " + buf + " s ago (limit " + std::to_string(gate.max_age_s).substr(0, 5) +
               " s either way: late, replayed, or a clock off)";
  }
  return v;
}

}  // namespace skelgraph::robot
