// skelgraph eval presence: listens to a running cell for a while with the
// `presence` component (eval::Presence) and says whether everyone in it was
// shown, whether departures were seen, and whether writers failed or kept
// instances of people who left.

#include <cstdio>
#include <memory>

#include "cli.hpp"
#include "run_graph.hpp"

namespace skelgraph::cli {

namespace {

struct PresenceOptions {
  double duration = 60.0;
  bool json = false, people = false, check = false;
};

const char* const kPeopleTopics[] = {"skelgraph/skeleton/raw", "skelgraph/skeleton/fused", "skelgraph/skeleton/truth",
                                     "skelgraph/gesture/state"};

// What --check fails on: a failed write, a departure missed or late, and, once
// nobody is left in the cell, any instance of a person still alive.
std::vector<std::string> problems(const nlohmann::json& r) {
  std::vector<std::string> out;
  if (r["failed_writes"].get<std::uint64_t>() > 0) out.push_back(std::to_string(r["failed_writes"].get<std::uint64_t>()) + " failed write(s)");
  const auto& d = r["departures"];
  if (d["late"].get<int>() > 0) out.push_back(std::to_string(d["late"].get<int>()) + " departure(s) seen late");
  if (d["still_shown"].get<int>() > 0) out.push_back(std::to_string(d["still_shown"].get<int>()) + " person(s) who left still shown");
  if (r["people"]["there_now"].get<int>() == 0) {
    for (const auto& o : r["outputs"]) {
      for (const char* t : kPeopleTopics) {
        if (o["topic"] == t && o["instances"].get<int>() > 0) {
          out.push_back(o["component"].get<std::string>() + " keeps " + std::to_string(o["instances"].get<int>()) +
                        " instance(s) on " + t + " with nobody in the cell");
        }
      }
    }
  }
  return out;
}

void print_text(const nlohmann::json& r) {
  const auto& p = r["people"];
  const auto& c = r["completeness"];
  const auto& d = r["departures"];
  std::printf("people: %d seen, %d left, %d there now\n", p["seen"].get<int>(), p["left"].get<int>(), p["there_now"].get<int>());
  std::printf("shown while tracked: %.1f %% of %.0f s", 100.0 * c["shown_of_tracked"].get<double>(), c["tracked_s"].get<double>());
  if (!c["min_person"].is_null()) {
    std::printf(" (per person: median %.1f %%, lowest %.1f %%, %d below 90 %%)", 100.0 * c["median_person"].get<double>(),
                100.0 * c["min_person"].get<double>(), c["people_below_90_percent"].get<int>());
  }
  std::printf("\ndepartures: %d of %d seen, %d late, %d still shown", d["seen"].get<int>(), d["people"].get<int>(),
              d["late"].get<int>(), d["still_shown"].get<int>());
  if (!d["after_inputs_ms"].is_null()) {
    std::printf("; after the trackers let go: median %.0f ms, max %.0f ms", d["after_inputs_ms"]["median"].get<double>(),
                d["after_inputs_ms"]["max"].get<double>());
  }
  std::printf("\nfailed writes: %llu\n", static_cast<unsigned long long>(r["failed_writes"].get<std::uint64_t>()));
  for (const auto& o : r["outputs"]) {
    std::printf("  %s %s: %d instance(s) now, at most %d", o["component"].get<std::string>().c_str(),
                o["topic"].get<std::string>().c_str(), o["instances"].get<int>(), o["max_instances"].get<int>());
    if (o.contains("max_instances_over_people")) std::printf(" (%lld beyond the people there)", o["max_instances_over_people"].get<long long>());
    if (o["failed_writes"].get<std::uint64_t>() > 0) std::printf(", %llu failed", static_cast<unsigned long long>(o["failed_writes"].get<std::uint64_t>()));
    std::printf("\n");
  }
}

int eval_presence(const PresenceOptions& o, GlobalOptions& g) {
  RunOptions ro;
  ro.duration_s = o.duration;
  std::fprintf(stderr, "listening to the cell for %.0f s (Ctrl-C ends it sooner)\n", o.duration);
  int verdict = 0;
  const int rc = run_components(
      g, {{"presence", "presence", {{"people", o.people ? "true" : "false", "eval presence --people"}}}}, ro,
      [&](runtime::Graph& graph, nlohmann::json&) {
        nlohmann::json r;
        for (const auto& n : graph.report()) {
          if (n.name == "presence") r = n.details;
        }
        if (r.is_null()) return;  // (it failed to start: the launcher said why)
        if (o.json) std::printf("%s\n", r.dump(2).c_str());
        else print_text(r);
        if (!o.check) return;
        for (const auto& p : problems(r)) {
          std::fprintf(stderr, "check: %s\n", p.c_str());
          verdict = 1;
        }
      });
  return rc != 0 ? rc : verdict;
}

}  // namespace

void add_eval_presence_command(CLI::App& eval, GlobalOptions& g, Action& run) {
  auto o = std::make_shared<PresenceOptions>();
  auto* c = eval.add_subcommand(
      "presence",
      "Who is in a running cell (ground truth) against who the graph shows: completeness per person, departures "
      "seen, failed writes, live instances against the people there");
  c->add_option("--duration", o->duration, "seconds to listen (Ctrl-C ends it sooner)")->check(kPositive);
  c->add_flag("--json", o->json, "machine-readable results");
  c->add_flag("--people", o->people, "every person in the results (with --json)");
  c->add_flag("--check", o->check,
              "exit 1 on a failed write, a departure seen late or not at all, or (with nobody left in the cell) an "
              "instance of a person still alive");
  add_dds_options(*c, g);
  c->callback([o, &g, &run] { run = [o, &g] { return eval_presence(*o, g); }; });
}

}  // namespace skelgraph::cli
