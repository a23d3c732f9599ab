// skelgraph topic list | echo TOPIC | hz TOPIC — like `ros2 topic`, from DDS discovery.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "cli.hpp"
#include "skelgraph/msg/message_table.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/discovery.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/rate_stats.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::cli {

namespace {

using Ms = std::chrono::milliseconds;

Ms seconds(double s) { return Ms(static_cast<std::int64_t>(s * 1000.0)); }

std::string participant_name(const char* what) {
  return std::string("skelgraph_topic_") + what + "_" + std::to_string(::getpid());
}

// A tool participant that watches discovery from its creation on.
struct ToolSession {
  runtime::DiscoveryObserver observer;
  std::unique_ptr<runtime::Context> context;
  ToolSession(const char* what, const runtime::DdsConfig& config) {
    context = std::make_unique<runtime::Context>(participant_name(what), config, &observer);
  }
};

// How to subscribe to `topic`: from our table if we know it, else from a writer discovered on the domain.
// A tool keeps up or drops, never blocks writers (keep-all becomes 1000); and it shows every sample it can:
// samples arriving together (the status of every component of a process) must not overwrite each other.
runtime::ReaderPlan plan_for(const std::string& topic, ToolSession& s, Ms timeout) {
  if (const auto* t = runtime::find_topic(topic)) return runtime::reader_plan(*t, 100, 1000);
  runtime::EndpointInfo w;
  if (!s.observer.wait_for_writer(topic, timeout, &w)) {
    throw UsageError("topic '" + topic + "': no writer found on domain " + std::to_string(s.context->config().domain) +
                     " within " + std::to_string(timeout.count()) + " ms (try `skelgraph topic list`)");
  }
  return runtime::ReaderPlan{w.type_name, w.keyed, {w.reliability, runtime::Durability::Volatile, 1000}};
}

int list(const runtime::DdsConfig& config, double wait_s, bool json, bool all) {
  const SignalHandling stops_gracefully;
  ToolSession s("list", config);
  wait_for_signal(seconds(wait_s));
  auto topics = s.observer.topics();
  if (!all) {
    // DDS-internal topics (e.g. ros_discovery_info) stay hidden unless asked for.
    topics.erase(std::remove_if(topics.begin(), topics.end(),
                                [](const runtime::TopicSummary& t) { return t.name.rfind("skelgraph/", 0) != 0; }),
                 topics.end());
  }
  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& t : topics) {
      out.push_back({{"name", t.name},
                     {"types", t.type_names},
                     {"writers", t.writers},
                     {"readers", t.readers},
                     {"participants", t.participants}});
    }
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::size_t w = 5;
  for (const auto& t : topics) w = std::max(w, t.name.size());
  std::printf("%-*s  %-34s %7s %7s\n", static_cast<int>(w), "TOPIC", "TYPE", "WRITERS", "READERS");
  for (const auto& t : topics) {
    std::string types;
    for (const auto& ty : t.type_names) types += (types.empty() ? "" : " | ") + ty;
    std::printf("%-*s  %-34s %7zu %7zu\n", static_cast<int>(w), t.name.c_str(), types.c_str(), t.writers, t.readers);
  }
  if (topics.empty()) std::fprintf(stderr, "no topics seen on domain %d within %.1f s\n", config.domain, wait_s);
  return 0;
}

int echo(const runtime::DdsConfig& config, const std::string& topic, std::size_t count, double timeout_s, bool json) {
  const SignalHandling stops_gracefully;
  ToolSession s("echo", config);
  const auto plan = plan_for(topic, s, seconds(timeout_s));
  const auto* info = msg::find_message(plan.type_name);
  std::mutex mutex;
  std::size_t printed = 0;
  runtime::RawSubscription sub(
      *s.context, topic, plan.type_name, plan.keyed, plan.qos,
      [&](const msg::RawSample& sample, const runtime::SampleMeta& meta) {
        nlohmann::json j;
        if (info != nullptr) {
          try {
            j = info->decode(sample.payload);
          } catch (const std::exception& e) {
            spdlog::warn("{}: {}", topic, e.what());
            return;
          }
        } else {
          j = {{"type", plan.type_name}, {"bytes", sample.payload.size()}};
        }
        std::lock_guard<std::mutex> lock(mutex);
        if (count > 0 && printed >= count) return;
        if (json) {
          std::printf("%s\n", nlohmann::json{{"topic", topic}, {"receive_ns", meta.receive_ns}, {"data", j}}.dump().c_str());
        } else {
          std::printf("%s\n---\n", j.dump(2).c_str());
        }
        std::fflush(stdout);
        ++printed;
      });
  s.context->executor().start();
  const auto deadline_first = std::chrono::steady_clock::now() + seconds(timeout_s);
  bool said_matched = false;
  while (true) {
    // Said once on stderr, so that a script can wait for the reader instead of sleeping.
    if (!said_matched && sub.matched() > 0) {
      std::fprintf(stderr, "echo: matched %zu writer(s) on %s\n", sub.matched(), topic.c_str());
      said_matched = true;
    }
    {
      std::unique_lock<std::mutex> lock(mutex);
      if (count > 0 && printed >= count) break;
      if (printed == 0 && timeout_s > 0 && std::chrono::steady_clock::now() >= deadline_first) {
        std::fprintf(stderr, "error: no sample on %s within %.1f s\n", topic.c_str(), timeout_s);
        return 1;
      }
    }
    if (wait_for_signal(Ms(100))) break;
  }
  s.context->executor().stop();
  return 0;
}

int hz(const runtime::DdsConfig& config, const std::string& topic, double window_s, double timeout_s, bool json,
       double duration_s) {
  const SignalHandling stops_gracefully;
  ToolSession s("hz", config);
  const auto plan = plan_for(topic, s, seconds(timeout_s));
  std::mutex mutex;
  const auto window_ns = static_cast<std::int64_t>(window_s * 1e9);
  runtime::RateStats stats(window_ns);
  auto mono_ns = [] { return runtime::system_clock()->monotonic_ns(); };
  std::int64_t first_ns = 0;
  runtime::RawSubscription sub(*s.context, topic, plan.type_name, plan.keyed, plan.qos,
                               [&](const msg::RawSample&, const runtime::SampleMeta&) {
                                 std::lock_guard<std::mutex> lock(mutex);
                                 const auto t = mono_ns();
                                 if (first_ns == 0) first_ns = t;
                                 stats.add(t);
                               });
  s.context->executor().start();
  const auto start = mono_ns();
  auto summary = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    stats.expire(mono_ns());
    return std::make_pair(stats.summary(), first_ns);
  };
  if (json) {
    // Wait for the first sample, then measure over one full window.
    while (true) {
      auto [sum, first] = summary();
      const auto now = mono_ns();
      if (first == 0 && now - start > static_cast<std::int64_t>(timeout_s * 1e9)) break;
      if (first != 0 && now - first >= window_ns) break;
      if (wait_for_signal(Ms(50))) break;
    }
    const auto [sum, first] = summary();
    s.context->executor().stop();
    nlohmann::json out = {{"topic", topic},
                          {"type", plan.type_name},
                          {"window_s", window_s},
                          {"samples", sum.samples},
                          {"rate_hz", sum.rate_hz},
                          {"mean_period_s", sum.mean_period_s},
                          {"min_period_s", sum.min_period_s},
                          {"max_period_s", sum.max_period_s},
                          {"std_period_s", sum.std_period_s}};
    std::printf("%s\n", out.dump(2).c_str());
    if (first == 0) std::fprintf(stderr, "error: no sample on %s within %.1f s\n", topic.c_str(), timeout_s);
    return first == 0 ? 1 : 0;
  }
  // Interactive: a line per second, until a signal or the duration.
  const auto end = duration_s > 0 ? start + static_cast<std::int64_t>(duration_s * 1e9) : INT64_MAX;
  while (mono_ns() < end) {
    if (wait_for_signal(Ms(1000))) break;
    const auto [sum, first] = summary();
    if (first == 0) {
      std::printf("waiting for %s ...\n", topic.c_str());
    } else {
      std::printf("average rate: %.3f Hz\n\tmin: %.4fs max: %.4fs std dev: %.5fs window: %zu\n", sum.rate_hz,
                  sum.min_period_s, sum.max_period_s, sum.std_period_s, sum.samples);
    }
    std::fflush(stdout);
  }
  s.context->executor().stop();
  return 0;
}

}  // namespace

void add_topic_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto* topic = app.add_subcommand("topic", "Inspect topics on the DDS domain (list, echo, hz)");
  topic->require_subcommand(1);

  struct Opts {
    std::string topic;
    double wait = 1.5;
    double timeout = 10.0;
    double window = 5.0;
    double duration = 0.0;
    std::size_t count = 0;
    bool json = false;
    bool all = false;
  };
  auto o = std::make_shared<Opts>();

  auto* l = topic->add_subcommand("list", "Topics seen on the domain, with type names and writer/reader counts");
  l->add_option("--wait", o->wait, "seconds to listen to discovery before printing")->check(kPositive);
  l->add_flag("--json", o->json, "print JSON");
  l->add_flag("--all", o->all, "include non-skelgraph topics");
  add_dds_options(*l, g);
  l->callback([o, &g, &run] { run = [o, &g] { return list(make_config(g), o->wait, o->json, o->all); }; });

  auto* e = topic->add_subcommand(
      "echo", "Print the samples published on a topic, decoded (stderr says 'echo: matched N writer(s)' once one is)");
  e->add_option("topic", o->topic, "topic name, e.g. skelgraph/sync")->required();
  e->add_option("--count", o->count, "exit after N samples (default: until Ctrl-C)");
  e->add_option("--timeout", o->timeout, "fail if nothing arrives within S seconds (0: wait forever)")
      ->check(kNonNegative);
  e->add_flag("--json", o->json, "one JSON object per line");
  add_dds_options(*e, g);
  e->callback([o, &g, &run] {
    run = [o, &g] { return echo(make_config(g), o->topic, o->count, o->timeout, o->json); };
  });

  auto* h = topic->add_subcommand("hz", "Measure a topic's publishing rate at this reader");
  h->add_option("topic", o->topic, "topic name")->required();
  h->add_option("--window", o->window, "seconds of arrivals the statistics cover")->check(kPositive);
  h->add_option("--timeout", o->timeout, "fail if nothing arrives within S seconds")->check(kPositive);
  h->add_option("--duration", o->duration, "stop after S seconds (interactive mode; default: until Ctrl-C)")
      ->check(kNonNegative);
  h->add_flag("--json", o->json,
              "measure one window after the first sample, print {rate_hz, samples, min/max/std period} and exit");
  add_dds_options(*h, g);
  h->callback([o, &g, &run] {
    run = [o, &g] { return hz(make_config(g), o->topic, o->window, o->timeout, o->json, o->duration); };
  });
}

}  // namespace skelgraph::cli
