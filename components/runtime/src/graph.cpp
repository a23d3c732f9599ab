#include "skelgraph/runtime/graph.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "skelgraph/msg/json.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/rate_stats.hpp"

namespace skelgraph::runtime {

namespace {
msg::ComponentState to_msg(HealthState s) {
  switch (s) {
    case HealthState::Ok: return msg::STATE_OK;
    case HealthState::Degraded: return msg::STATE_DEGRADED;
    case HealthState::Error: return msg::STATE_ERROR;
  }
  return msg::STATE_ERROR;
}
const char* to_text(HealthState s) { return msg::to_string(to_msg(s)); }

}  // namespace

// Members are destroyed bottom-up: the component first, then the status
// writer, then the context (participant) — the reverse of creation.
struct Graph::Node {
  std::string name;
  std::string kind;
  Params params;
  std::int64_t created_ns = 0;   // monotonic: when the context (participant) was made
  int restarts = 0;
  std::unique_ptr<Context> context;
  std::unique_ptr<Publisher<msg::ComponentStatus>> status;
  std::unique_ptr<Component> component;
  TimerHandle status_timer;
  std::map<std::string, std::uint64_t> last_counts;  // executor thread only
  std::int64_t last_report_ns = 0;

  std::set<std::string> stalls_reported;  // executor thread only

  void publish_status() {
    for (const auto& p : context->unauthenticated(Graph::kAuthStall)) {
      if (stalls_reported.insert(p.who).second) {
        std::fprintf(stderr, "%s: DDS participant %s has not finished authenticating after %lld s\n",
                     context->name().c_str(), p.who.c_str(), static_cast<long long>(Graph::kAuthStall.count() / 1000));
      }
    }
    msg::ComponentStatus s;
    s.component_name(context->name());
    s.kind(kind);
    s.host(context->config().host);
    const auto now = context->clock().now_ns();
    s.stamp_ns(now);
    const auto [state, message] = context->health();
    s.state(to_msg(state));
    s.message(message.substr(0, 255));
    const double dt = last_report_ns > 0 ? static_cast<double>(now - last_report_ns) * 1e-9 : 0.0;
    for (const auto& c : context->counters()) {
      if (c->topic == topics::kStatus.name || s.topics().size() >= 32) continue;
      msg::TopicStats t;
      t.topic(c->topic);
      t.is_output(c->is_output);
      const auto count = c->count.load();
      const auto key = (c->is_output ? "out:" : "in:") + c->topic;
      t.count(count);
      t.rate_hz(dt > 0.0 ? static_cast<double>(count - last_counts[key]) / dt : 0.0);
      t.dropped(c->dropped.load());
      t.instances(static_cast<std::uint32_t>(c->instances.load()));
      last_counts[key] = count;
      s.topics().push_back(t);
    }
    last_report_ns = now;
    status->publish(s);
  }
};

Graph::Graph(const ComponentRegistry& registry, DdsConfig config, std::chrono::milliseconds status_period)
    : registry_(registry), config_(std::move(config)), status_period_(status_period) {}

Graph::~Graph() {
  stop();
  // Reverse order of creation.
  while (!nodes_.empty()) nodes_.pop_back();
}

void Graph::simulate_auth_stall(std::string name, std::chrono::nanoseconds after) {
  stall_name_ = std::move(name);
  stall_after_ns_ = after.count();
}

Component& Graph::add(const std::string& name, const std::string& kind, const Params& params) {
  if (started_) throw std::logic_error("Graph::add after start");
  for (const auto& n : nodes_) {
    if (n->context->name() == name) throw std::runtime_error("component name '" + name + "' used twice");
  }
  const auto* entry = registry_.find(kind);
  if (entry == nullptr) throw std::runtime_error("component '" + name + "': unknown type '" + kind + "'");
  auto node = std::make_unique<Node>();
  node->name = name;
  node->kind = kind;
  node->params = params;
  build(*node);
  nodes_.push_back(std::move(node));
  return *nodes_.back()->component;
}

void Graph::build(Node& node) {
  node.context = std::make_unique<Context>(node.name, config_);
  node.created_ns = node.context->clock().monotonic_ns();
  node.status = std::make_unique<Publisher<msg::ComponentStatus>>(*node.context, topics::kStatus);
  try {
    node.component = registry_.find(node.kind)->factory(*node.context, node.params);
  } catch (const std::exception& e) {
    throw std::runtime_error("component '" + node.name + "' (" + node.kind + "): " + e.what());
  }
}

void Graph::start_node(Node* node) {
  node->context->executor().start();
  node->context->executor().post([node] { node->component->on_start(); });
  node->status_timer = node->context->executor().every(status_period_, [node] { node->publish_status(); });
}

void Graph::shut_down(Node* node) {
  node->context->executor().run_sync(
      [node] {
        node->status_timer.cancel();
        node->component->on_shutdown();
      },
      std::chrono::seconds(5));
}

std::vector<std::string> Graph::heal(std::chrono::milliseconds stall, int max_restarts) {
  std::vector<std::string> restarted;
  if (!started_ || stopped_) return restarted;
  const auto stall_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(stall).count();
  for (auto it = nodes_.begin(); it != nodes_.end();) {
    Node* node = it->get();
    ++it;
    if (node->restarts >= max_restarts) continue;
    // Peers met at this participant's start: the newcomer is the one to start
    // over (a stuck newcomer elsewhere restarts itself), so a stranger or a
    // tool joining later does not restart a running component; unless the
    // peer did start over and is stuck with us again: then the fault is on
    // our side.
    std::vector<std::string> stuck;
    for (const auto& p : node->context->unauthenticated(stall)) {
      if (p.since_ns - node->created_ns <= stall_ns / 2 || p.again) stuck.push_back(p.who);
    }
    if (node->restarts == 0 && !stall_name_.empty() && stall_name_ == node->name &&
        node->context->clock().monotonic_ns() - node->created_ns > stall_after_ns_) {
      stuck.push_back("'test' (simulated)");
    }
    if (stuck.empty()) continue;
    std::string who;
    for (const auto& w : stuck) who += (who.empty() ? "" : ", ") + w;
    std::fprintf(stderr,
                 "%s: restarting it with a new DDS participant: %s never finished authenticating with it "
                 "(Fast DDS 2.9 leaves such a pair for good; docs/security.md)\n",
                 node->name.c_str(), who.c_str());
    shut_down(node);
    node->context->flush(std::chrono::milliseconds(500));
    node->context->executor().stop();
    node->component.reset();
    node->status.reset();
    node->context.reset();
    ++node->restarts;
    try {
      build(*node);
    } catch (const std::exception& e) {
      // Gone from this launch; the final report names it (state ERROR).
      std::fprintf(stderr, "%s: could not be started again: %s\n", node->name.c_str(), e.what());
      lost_.push_back({node->name, node->kind, "ERROR", std::string("could not be started again: ") + e.what(), {}, {}, nullptr});
      it = nodes_.erase(it - 1);
      continue;
    }
    start_node(node);
    restarted.push_back(node->name);
  }
  return restarted;
}

bool Graph::finished() const {
  bool any = false;
  for (const auto& n : nodes_) {
    if (!n->component->finite()) continue;
    if (!n->component->finished()) return false;
    any = true;
  }
  return any;
}

void Graph::add_all(const std::vector<ResolvedComponent>& components) {
  for (const auto& c : components) add(c.name, c.kind, c.params);
}

std::vector<std::string> Graph::await_matches(std::chrono::milliseconds timeout) const {
  struct End {
    const std::string* component;
    std::shared_ptr<EndpointCounter> counter;
  };
  std::vector<End> ends;
  for (const auto& n : nodes_) {
    for (auto& c : n->context->counters()) ends.push_back({&n->name, std::move(c)});
  }
  // What each endpoint must have matched inside the graph: the other side's
  // endpoints on its topic whose QoS fit (a writer offers at least what a reader asks).
  std::vector<std::size_t> want(ends.size(), 0);
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const auto& a = *ends[i].counter;
    for (const auto& e : ends) {
      const auto& b = *e.counter;
      if (b.topic != a.topic || b.is_output == a.is_output) continue;
      const auto& w = a.is_output ? a : b;
      const auto& r = a.is_output ? b : a;
      if ((w.reliable || !r.reliable) && (w.transient_local || !r.transient_local)) ++want[i];
    }
  }
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::vector<std::string> missing;
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (ends[i].counter->wait_matched(want[i], std::max(left, std::chrono::milliseconds(0)))) continue;
    missing.push_back(*ends[i].component + (ends[i].counter->is_output ? " writing " : " reading ") +
                      ends[i].counter->topic + " (" + std::to_string(ends[i].counter->matched()) + " of " +
                      std::to_string(want[i]) + " matched)");
  }
  return missing;
}

void Graph::start() {
  if (started_) return;
  started_ = true;
  // Components start once they hear each other: a sync session, say, begins
  // only when every fusion component's reader has matched its writer (on a
  // busy machine discovery can take seconds, and volatile ticks sent before
  // a match never reach that reader).
  const auto missing = await_matches(kMatchWait);
  if (!missing.empty()) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : "; ") + m;
    std::fprintf(stderr, "graph: starting although, after %lld s, DDS has not matched inside the graph: %s\n",
                 static_cast<long long>(kMatchWait.count() / 1000), list.c_str());
  }
  for (auto& n : nodes_) start_node(n.get());
}

void Graph::stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  // 1. Every component's last words (a STOP, say) while all still listen;
  // 2. wait until reliable readers have them; 3. stop the executors, which
  // first run what is already queued.
  for (auto it = nodes_.rbegin(); it != nodes_.rend(); ++it) shut_down(it->get());
  for (auto& n : nodes_) n->context->flush(std::chrono::milliseconds(1000));
  for (auto it = nodes_.rbegin(); it != nodes_.rend(); ++it) (*it)->context->executor().stop();
}

std::vector<NodeReport> Graph::report() const {
  std::vector<NodeReport> out(lost_);
  for (const auto& n : nodes_) {
    NodeReport r;
    r.name = n->context->name();
    r.kind = n->kind;
    // A write that failed at any time in the run leaves the report DEGRADED.
    const auto [state, message] = n->context->health(std::chrono::nanoseconds::max());
    r.state = to_text(state);
    r.message = message;
    r.summary = n->component->summary();
    r.details = n->component->details();
    std::ostringstream io;
    for (const auto& c : n->context->counters()) {
      if (c->topic == topics::kStatus.name) continue;
      io << (io.tellp() > 0 ? ", " : "") << (c->is_output ? "out " : "in ") << c->topic << " " << c->count.load();
      if (c->dropped.load() > 0) io << " (" << c->dropped.load() << " dropped)";
    }
    r.io = io.str();
    out.push_back(std::move(r));
  }
  return out;
}

Context& Graph::context(const std::string& name) {
  for (auto& n : nodes_) {
    if (n->context->name() == name) return *n->context;
  }
  throw std::out_of_range("no component named '" + name + "'");
}

}  // namespace skelgraph::runtime
