#pragma once
// Launch files (YAML) list the components of a graph and the host each runs on:
//
//   profile: loopback          # optional: DDS profile (bringup/profiles/<name>.xml)
//   domain: 0                  # optional: DDS domain id
//   components:
//     - name: sync             # unique; also the DomainParticipant's name
//       type: sync_master      # a registered component kind
//       host: fusion           # optional: a host name or a list of them
//       params: {tick_period_ms: 33}
//
// Parsing and checking need no DDS, so they are unit-tested on their own.

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "skelgraph/runtime/params.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::runtime {

class LaunchError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ComponentSpec {
  std::string name;
  std::string kind;
  std::vector<std::string> hosts;  // empty: the component is not tied to a host
  std::vector<RawParam> params;
  std::string origin;              // file:line of the entry
};

struct LaunchSpec {
  std::string source;              // file path, or a label for embedded text
  std::optional<std::string> profile;
  std::optional<int> domain;
  std::vector<ComponentSpec> components;
};

// Throws LaunchError naming source:line:column and what was expected.
LaunchSpec parse_launch_file(const std::string& path);
LaunchSpec parse_launch_text(const std::string& text, const std::string& source);

// Sets parameters from the command line, each "COMPONENT.KEY=VALUE" (a list
// value as "a,b"), over what the file says; checked with the rest by
// resolve_launch. Throws LaunchError for a malformed one or an unknown component.
void set_launch_params(LaunchSpec& spec, const std::vector<std::string>& assignments);

struct ResolvedComponent {
  std::string name;
  std::string kind;
  Params params;
};

// Picks the components for `host` (all when empty; with a host, those listing
// it), checks kinds and parameters against the registry. Throws LaunchError
// with every problem found.
std::vector<ResolvedComponent> resolve_launch(const LaunchSpec& spec, const ComponentRegistry& registry,
                                              const std::string& host);

}  // namespace skelgraph::runtime
