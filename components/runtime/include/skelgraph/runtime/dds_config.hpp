#pragma once
// How a process joins DDS: which XML profile, which domain, which interfaces.

#include <memory>
#include <string>
#include <vector>

#include "skelgraph/runtime/clock.hpp"

namespace skelgraph::runtime {

struct DdsConfig {
  // A profile name (bringup/profiles/<name>.xml, participant profile <name>)
  // or a path to an XML file whose participant profile has the file's stem as name.
  std::string profile = "loopback";
  int domain = 0;
  // UDP interfaces to use (lan); empty keeps what the profile says.
  std::vector<std::string> interfaces;
  // Discovery servers ("IP:PORT", the i-th being server id i, as `fastdds
  // discovery -i i` starts it): when set, the participant is their client
  // (no multicast discovery). Profiles that are clients need at least one.
  std::vector<std::string> discovery_servers;
  // DDS Security credentials made by `skelgraph security init` (ca.pem,
  // governance.p7s, permissions.p7s, hosts/<host>.pem and .key): when set, the
  // participant authenticates as `host` and encrypts as the governance says.
  // The `secure` profile requires it.
  std::string security_dir;
  // Reported in status messages and sync acks; the identity under security.
  std::string host;
  // The clock of every component made with this configuration (Context::clock()).
  std::shared_ptr<const Clock> clock = system_clock();

  // Defaults from the environment: SKELGRAPH_PROFILE, SKELGRAPH_DOMAIN,
  // SKELGRAPH_INTERFACES (comma-separated), SKELGRAPH_DISCOVERY_SERVERS
  // (comma-separated IP:PORT), SKELGRAPH_SECURITY_DIR, SKELGRAPH_HOST (else
  // the host name).
  // Throws std::runtime_error on a malformed value.
  static DdsConfig from_env();
};

// An "IP:PORT" discovery server address (IPv4 dotted quad, port 1..65535).
// Throws std::runtime_error saying what is wrong.
struct ServerAddress {
  std::string ip;
  int port = 0;
};
ServerAddress parse_server_address(const std::string& text);

// Directory holding the profile XML files: $SKELGRAPH_PROFILES_DIR, else the
// source tree's bringup/profiles (the build-tree program), else ./bringup/profiles.
std::string profiles_dir();
// The XML file for a profile name or path; throws std::runtime_error if absent.
std::string profile_file(const std::string& profile);
// The participant profile name inside that file.
std::string profile_name(const std::string& profile);

}  // namespace skelgraph::runtime
