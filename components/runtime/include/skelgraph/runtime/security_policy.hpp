#pragma once
// The DDS Security policy of a cell (`skelgraph security init|check`): the
// roles a host may have, what each may publish (every host may subscribe to
// everything), a host's grant from its roles, and the governance and
// permissions documents (DDS Security 1.1 XML, before signing). The robot's
// topics are published only by the robot host (its state) and robot-control
// hosts (commands, the safety verdict): a master gets a deny rule for those
// its other roles do not give it. No files, no openssl: see docs/security.md.

#include <string>
#include <utility>
#include <vector>

namespace skelgraph::runtime::security {

// master, sensor, reader, robot, robot-control.
const std::vector<std::string>& roles();
// skelgraph/robot/state, skelgraph/robot/command, skelgraph/safety.
std::vector<std::string> robot_topics();
// What a role may publish ("*": every topic).
std::vector<std::string> role_publishes(const std::string& role);

struct Grant {
  std::vector<std::string> publish;  // allowed ("*": everything not denied)
  std::vector<std::string> deny;     // denied first (a deny rule before the allow rule)
};
// The union of what the roles publish; a master is denied the robot topics the other roles do not give.
Grant grant_of(const std::vector<std::string>& roles);

using Hosts = std::vector<std::pair<std::string, std::vector<std::string>>>;  // host, roles
std::string governance_xml();
// One grant per host (subject CN=host), valid from..until (ISO 8601 UTC).
std::string permissions_xml(const Hosts& hosts, const std::string& from, const std::string& until);
// A host name fit for a certificate's CN and a file name: 1-64 of [A-Za-z0-9-_.].
bool valid_host(const std::string& h);

}  // namespace skelgraph::runtime::security
