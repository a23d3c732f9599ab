#pragma once
// Shared pieces of the `skelgraph` command-line program.

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "skelgraph/playback/readers.hpp"
#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/launch_file.hpp"

namespace skelgraph::sim {
struct SimConfig;
}

namespace skelgraph::cli {

// Bad input from the user (exit code 2); other exceptions exit with 1.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
template <class... Errors>
struct AsUsage;
template <>
struct AsUsage<> {
  template <class F>
  static auto run(F& f) {
    return f();
  }
};
template <class E, class... Rest>
struct AsUsage<E, Rest...> {
  template <class F>
  static auto run(F& f) {
    try {
      return AsUsage<Rest...>::run(f);
    } catch (const E& e) {
      throw UsageError(e.what());
    }
  }
};
}  // namespace detail

// Runs f(); a library error of one of the types Errors is the user's input:
// rethrown as a UsageError (exit 2) with its message.
template <class... Errors, class F>
auto user_input(F&& f) {
  return detail::AsUsage<Errors...>::run(f);
}

// A batch of input files in which one bad file does not stop the others: each
// problem is printed on stderr as it is met ("error: FILE:LINE: what"), the
// rest is processed, and the command exits 2 (bad input) at the end.
class BadInputs {
 public:
  // Runs f(); a playback::DataError or UsageError from it is reported and counted. True if f() finished.
  template <class F>
  bool guard(F&& f) {
    try {
      f();
      return true;
    } catch (const playback::DataError& e) {
      add(e.what());
    } catch (const UsageError& e) {
      add(e.what());
    }
    return false;
  }
  void add(const std::string& message);
  std::size_t count() const { return messages_.size(); }
  const std::vector<std::string>& messages() const { return messages_; }
  // `rc` when every input was good; else 2, after "N of M inputs were bad" on stderr.
  int exit_code(int rc, std::size_t inputs) const;

 private:
  std::vector<std::string> messages_;
};

// On stderr, "note: FILE: N bad lines of M skipped (first: ...)" when a read skipped lines.
void note_skipped(const playback::Recording& recording);

struct GlobalOptions {
  std::optional<int> domain;
  std::optional<std::string> profile;
  std::vector<std::string> interfaces;
  std::vector<std::string> discovery_servers;
  std::optional<std::string> security_dir;
  double clock_offset_ms = 0.0;  // this process plays a host whose clock is off by this much (tests)
  std::string log_level = "info";
};

// DDS settings: command line, then environment, then launch file, then defaults.
runtime::DdsConfig make_config(const GlobalOptions& g, const runtime::LaunchSpec* spec = nullptr);

// Progress of long work, on stderr so that stdout (tables, --json) stays
// clean. On a terminal one line redrawn in place; otherwise (a log, CI) a
// line at most every 10 s, plus the last one, so logs stay short. Disabled:
// nothing. done() ends the line, keeping it or clearing it.
class Progress {
 public:
  explicit Progress(bool enabled = true);
  ~Progress() { done(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void operator()(const std::string& text, bool last = false);
  void done(bool keep = true);

 private:
  bool enabled_, tty_;
  std::string shown_;  // the line on the terminal now
  std::chrono::steady_clock::time_point logged_{};
};

// Option checks with messages a user can read ("must be >= 0, got -3").
extern const CLI::Validator kNonNegative;
extern const CLI::Validator kPositive;

// Adds --domain/--profile/--interface to a subcommand that talks DDS.
void add_dds_options(CLI::App& cmd, GlobalOptions& g);

// SIGINT/SIGTERM are blocked in every thread from the start (DDS threads never
// see them) and taken by one watcher thread. Where a command has said it stops
// gracefully (a SignalHandling in scope: a running graph, `topic echo`), a
// signal is handed to wait_for_signal; anywhere else (offline work: eval,
// gesture cv, the demo's report) it ends the process at once, exit 128 + the
// signal, as Ctrl-C does to any command-line tool. A second signal always does.
void block_signals();
// True if a signal arrived within `timeout` (only while a SignalHandling is in scope).
bool wait_for_signal(std::chrono::milliseconds timeout);
// Whether a signal has arrived since the process started (handled or not yet).
bool interrupted();
class SignalHandling {
 public:
  SignalHandling();
  ~SignalHandling();
  SignalHandling(const SignalHandling&) = delete;
  SignalHandling& operator=(const SignalHandling&) = delete;
};

// Each adds a subcommand; when the user picks it, `run` is set to its action.
using Action = std::function<int()>;
void add_launch_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_run_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_play_data_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_topic_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_sync_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_robot_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_player_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_security_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_demo_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_components_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_sim_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_bag_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_eval_command(CLI::App& app, GlobalOptions& g, Action& run);
// `eval presence`, added by add_eval_command.
void add_eval_presence_command(CLI::App& eval, GlobalOptions& g, Action& run);
// `eval safety`, added by add_eval_command.
void add_eval_safety_command(CLI::App& eval, Action& run);
void add_fuse_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_calib_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_gesture_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_depth_command(CLI::App& app, GlobalOptions& g, Action& run);
void add_oni_command(CLI::App& app, GlobalOptions& g, Action& run);  // with SKELGRAPH_WITH_OPENNI2

// The simulator's configuration from -p KEY=VALUE assignments (then `extra`,
// e.g. {"scenario", "walk"}), checked by building a simulation; UsageError
// naming `what` on bad input. Every offline command that simulates uses it.
sim::SimConfig sim_config(const std::vector<std::string>& assignments, const char* what,
                          const std::vector<runtime::RawParam>& extra = {});

}  // namespace skelgraph::cli
