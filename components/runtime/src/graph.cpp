#include "skelgraph/runtime/graph.hpp"

#include <map>
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
  std::string kind;
  std::unique_ptr<Context> context;
  std::unique_ptr<Publisher<msg::ComponentStatus>> status;
  std::unique_ptr<Component> component;
  TimerHandle status_timer;
  std::map<std::string, std::uint64_t> last_counts;  // executor thread only
  std::int64_t last_report_ns = 0;

  void publish_status() {
    msg::ComponentStatus s;
    s.component_name(context->name());
    s.kind(kind);
    s.host(context->config().host);
    const auto now = Context::now_ns();
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

Component& Graph::add(const std::string& name, const std::string& kind, const Params& params) {
  if (started_) throw std::logic_error("Graph::add after start");
  for (const auto& n : nodes_) {
    if (n->context->name() == name) throw std::runtime_error("component name '" + name + "' used twice");
  }
  const auto* entry = registry_.find(kind);
  if (entry == nullptr) throw std::runtime_error("component '" + name + "': unknown type '" + kind + "'");
  auto node = std::make_unique<Node>();
  node->kind = kind;
  node->context = std::make_unique<Context>(name, config_);
  node->status = std::make_unique<Publisher<msg::ComponentStatus>>(*node->context, topics::kStatus);
  try {
    node->component = entry->factory(*node->context, params);
  } catch (const std::exception& e) {
    throw std::runtime_error("component '" + name + "' (" + kind + "): " + e.what());
  }
  nodes_.push_back(std::move(node));
  return *nodes_.back()->component;
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

void Graph::start() {
  if (started_) return;
  started_ = true;
  for (auto& n : nodes_) {
    Node* node = n.get();
    node->context->executor().start();
    node->context->executor().post([node] { node->component->on_start(); });
    node->status_timer = node->context->executor().every(status_period_, [node] { node->publish_status(); });
  }
}

void Graph::stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  // 1. Every component's last words (a STOP, say) while all still listen;
  // 2. wait until reliable readers have them; 3. stop the executors, which
  // first run what is already queued.
  for (auto it = nodes_.rbegin(); it != nodes_.rend(); ++it) {
    Node* node = it->get();
    node->context->executor().run_sync(
        [node] {
          node->status_timer.cancel();
          node->component->on_shutdown();
        },
        std::chrono::seconds(5));
  }
  for (auto& n : nodes_) n->context->flush(std::chrono::milliseconds(1000));
  for (auto it = nodes_.rbegin(); it != nodes_.rend(); ++it) (*it)->context->executor().stop();
}

std::vector<NodeReport> Graph::report() const {
  std::vector<NodeReport> out;
  for (const auto& n : nodes_) {
    NodeReport r;
    r.name = n->context->name();
    r.kind = n->kind;
    const auto [state, message] = n->context->health();
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
