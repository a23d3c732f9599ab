#pragma once
// Base of every component. The constructor (Context&, const Params&) does all
// the wiring; callbacks then run on the context's executor. Subclasses are
// `final`, keep their logic in a DDS-free core, and end their .cpp with
// SKELGRAPH_REGISTER_COMPONENT(kind, Class).

#include <string>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/params.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::runtime {

class Component {
 public:
  explicit Component(Context& ctx) : ctx_(ctx) {}
  virtual ~Component() = default;
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  // Run on the executor: first thing after start, last thing before stop.
  virtual void on_start() {}
  virtual void on_shutdown() {}
  // One line for the launcher's report ("42 ticks, session 7").
  virtual std::string summary() const { return {}; }
  // A component with an end (a player at the end of its file) says so; a run
  // of the graph ends when every such component has finished. Thread-safe.
  virtual bool finite() const { return false; }
  virtual bool finished() const { return false; }
  // The same, machine-readable, for `--json` reports (null when there is nothing).
  virtual nlohmann::json details() const { return nullptr; }

 protected:
  Context& ctx_;
};

}  // namespace skelgraph::runtime
