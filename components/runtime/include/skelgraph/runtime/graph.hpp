#pragma once
// A set of components composed in one process: each gets its own Context
// (DomainParticipant + executor) and reports ComponentStatus once a second.
// Used by `skelgraph launch`, the demo and the component tests alike.

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/launch_file.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::runtime {

class Component;
class Context;

struct NodeReport {
  std::string name;
  std::string kind;
  std::string state;    // OK / DEGRADED / ERROR
  std::string message;
  std::string summary;  // the component's own line
  std::string io;       // "out skelgraph/sync 181, in ... " counts
  nlohmann::json details;  // the component's own machine-readable report
};

class Graph {
 public:
  Graph(const ComponentRegistry& registry, DdsConfig config,
        std::chrono::milliseconds status_period = std::chrono::seconds(1));
  ~Graph();
  Graph(const Graph&) = delete;
  Graph& operator=(const Graph&) = delete;

  // Creates the component (its constructor runs here; exceptions propagate
  // with the component's name prepended).
  Component& add(const std::string& name, const std::string& kind, const Params& params);
  void add_all(const std::vector<ResolvedComponent>& components);

  // Waits (at most kMatchWait) until DDS has matched every reader and writer
  // of the graph with their counterparts inside it, then starts every
  // executor and on_start() of each component. What did not match in time is
  // named on stderr.
  void start();
  static constexpr std::chrono::milliseconds kMatchWait{10000};
  // The endpoints not matched with all their counterparts in the graph within
  // `timeout`, as "component reading topic (n of m matched)".
  std::vector<std::string> await_matches(std::chrono::milliseconds timeout) const;
  void stop();   // on_shutdown() of each (reverse order), then stops executors; idempotent

  // A secure peer not authenticated after this long is stuck (a handshake takes 1-2 s).
  static constexpr std::chrono::milliseconds kAuthStall{10000};

  // Secure profiles: a component whose participant has a peer stuck in
  // authentication for `stall` is started over with a new participant, since
  // Fast DDS 2.9 never retries such a pair: when it met that peer at its own
  // start (the newcomer restarts), or when the same component of the same
  // host is stuck with it again after restarting. At most `max_restarts`
  // times each. Returns the components restarted. Call from the thread that
  // owns the graph, after start().
  std::vector<std::string> heal(std::chrono::milliseconds stall = kAuthStall, int max_restarts = 3);
  // For tests of heal() without a secure cell that happens to hit the Fast DDS
  // defect: component `name` counts as stuck once `after` its start.
  void simulate_auth_stall(std::string name, std::chrono::nanoseconds after);

  // True when the graph has components with an end and all of them have finished.
  bool finished() const;

  // Call after stop(): components are not locked while they report.
  std::vector<NodeReport> report() const;
  Context& context(const std::string& name);

 private:
  struct Node;
  void build(Node& node);  // context, status writer and component, from the node's name, kind and params
  void start_node(Node* node);
  void shut_down(Node* node);  // on_shutdown() on the node's executor
  const ComponentRegistry& registry_;
  DdsConfig config_;
  std::chrono::milliseconds status_period_;
  std::vector<std::unique_ptr<Node>> nodes_;
  std::vector<NodeReport> lost_;  // components a restart could not bring back
  std::string stall_name_;        // simulate_auth_stall
  std::int64_t stall_after_ns_ = 0;
  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace skelgraph::runtime
