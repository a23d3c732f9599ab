#include "run_graph.hpp"

#include <chrono>
#include <cstdio>

#include <spdlog/spdlog.h>

#include "cli.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

namespace {
void print_reports(const runtime::Graph& graph, const char* when) {
  for (const auto& r : graph.report()) {
    std::fprintf(stderr, "[%s] %s (%s) %s%s%s%s%s\n", when, r.name.c_str(), r.kind.c_str(), r.state.c_str(),
                 r.message.empty() ? "" : (" - " + r.message).c_str(), r.summary.empty() ? "" : ": ",
                 r.summary.c_str(), r.io.empty() ? "" : (" | " + r.io).c_str());
  }
}
}  // namespace

void add_run_options(CLI::App& cmd, RunOptions& options) {
  cmd.add_option("--duration", options.duration_s, "stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(kNonNegative);
  cmd.add_option("--status-every", options.status_every_s, "print each component's status line every S seconds")
      ->check(kNonNegative);
  cmd.add_flag("--json", options.json, "print the final report as JSON on stdout");
  cmd.add_option("--test-auth-stall", options.auth_stall,
                 "NAME@SECONDS: component NAME counts as stuck in DDS Security authentication that long after its "
                 "start, once, so that its restart can be tested without a cell that hits the Fast DDS defect")
      ->group("");  // hidden: for tests
}

int run_components(GlobalOptions& g, const std::vector<ComponentRun>& list, const RunOptions& options,
                   const std::function<void(runtime::Graph&, nlohmann::json&)>& extra_report) {
  const auto registry = runtime::builtin_registry();
  std::vector<runtime::ResolvedComponent> graph;
  for (const auto& r : list) {
    runtime::ResolvedComponent c;
    c.name = r.name;
    c.kind = r.kind;
    try {
      c.params = registry.find(r.kind)->info.params.resolve(r.raw, "component '" + r.name + "'");
    } catch (const runtime::ParamError& e) {
      throw UsageError(e.what());
    }
    graph.push_back(std::move(c));
  }
  return run_graph(registry, make_config(g), graph, options, extra_report);
}

std::string recorded_file(const runtime::Graph& graph) {
  for (const auto& r : graph.report()) {
    if (r.kind != "recorder") continue;
    for (const auto& f : r.details.value("files", nlohmann::json::array())) return f.value("file", "");
  }
  return {};
}

int run_graph(const runtime::ComponentRegistry& registry, const runtime::DdsConfig& config,
              const std::vector<runtime::ResolvedComponent>& components, const RunOptions& options,
              const std::function<void(runtime::Graph&, nlohmann::json&)>& extra_report) {
  runtime::Graph graph(registry, config);
  if (!options.auth_stall.empty()) {
    const auto at = options.auth_stall.find('@');
    double secs = 0;
    try {
      secs = at == std::string::npos ? -1 : std::stod(options.auth_stall.substr(at + 1));
    } catch (const std::exception&) {
      secs = -1;
    }
    if (at == 0 || secs < 0) throw UsageError("--test-auth-stall " + options.auth_stall + ": expected NAME@SECONDS");
    graph.simulate_auth_stall(options.auth_stall.substr(0, at), std::chrono::nanoseconds(static_cast<std::int64_t>(secs * 1e9)));
  }
  graph.add_all(components);
  graph.start();
  for (const auto& c : components) {
    std::fprintf(stderr, "[start] %s (%s) on domain %d, profile %s, host %s\n", c.name.c_str(), c.kind.c_str(),
                 config.domain, config.profile.c_str(), config.host.c_str());
  }
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const auto end = options.duration_s > 0
                       ? t0 + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(options.duration_s))
                       : clock::time_point::max();
  auto next_status = options.status_every_s > 0
                         ? t0 + std::chrono::duration_cast<clock::duration>(
                                    std::chrono::duration<double>(options.status_every_s))
                         : clock::time_point::max();
  const SignalHandling stops_gracefully;  // a signal ends the loop below; the graph is stopped and reported
  bool signalled = false;
  auto next_heal = t0;
  while (!signalled) {
    const auto now = clock::now();
    if (now >= end) break;
    if (now >= next_heal) {
      graph.heal();  // secure profiles: a component stuck in authentication starts over
      next_heal = now + std::chrono::seconds(1);
    }
    if (graph.finished()) {
      spdlog::info("every component with an end has finished, stopping");
      break;
    }
    const auto until = std::min({end, next_status, now + std::chrono::milliseconds(100)});
    signalled = wait_for_signal(std::chrono::duration_cast<std::chrono::milliseconds>(until - now) +
                                std::chrono::milliseconds(1));
    if (clock::now() >= next_status) {
      print_reports(graph, "status");
      next_status += std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(options.status_every_s));
    }
  }
  if (signalled) spdlog::info("signal received, stopping");
  graph.stop();
  print_reports(graph, "stop");
  nlohmann::json report;
  report["components"] = nlohmann::json::array();
  bool failed = false;
  for (const auto& r : graph.report()) {
    failed = failed || r.state == "ERROR";
    report["components"].push_back(
        {{"name", r.name}, {"kind", r.kind}, {"state", r.state}, {"message", r.message}, {"summary", r.summary}, {"io", r.io},
         {"details", r.details}});
  }
  report["duration_s"] = std::chrono::duration<double>(clock::now() - t0).count();
  report["domain"] = config.domain;
  report["profile"] = config.profile;
  if (extra_report) extra_report(graph, report);
  if (options.json) std::printf("%s\n", report.dump(2).c_str());
  return failed ? 1 : 0;  // a component that ended in ERROR (the report says why)
}

}  // namespace skelgraph::cli
