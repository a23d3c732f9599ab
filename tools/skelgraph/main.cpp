// skelgraph: the command-line front end (launch, topic, sync, demo, components).

#include <pthread.h>

#include <algorithm>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <unistd.h>

#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "cli.hpp"
#include "skelgraph/gesture/hmm.hpp"

namespace skelgraph::cli {

runtime::DdsConfig make_config(const GlobalOptions& g, const runtime::LaunchSpec* spec) {
  auto c = runtime::DdsConfig::from_env();
  const bool env_domain = std::getenv("SKELGRAPH_DOMAIN") != nullptr;
  const bool env_profile = std::getenv("SKELGRAPH_PROFILE") != nullptr;
  if (spec != nullptr) {
    if (spec->domain && !env_domain) c.domain = *spec->domain;
    if (spec->profile && !env_profile) c.profile = *spec->profile;
  }
  if (g.domain) c.domain = *g.domain;
  if (g.profile) c.profile = *g.profile;
  if (!g.interfaces.empty()) c.interfaces = g.interfaces;
  if (g.security_dir) c.security_dir = *g.security_dir;
  if (!g.discovery_servers.empty()) {
    for (const auto& a : g.discovery_servers) runtime::parse_server_address(a);
    c.discovery_servers = g.discovery_servers;
  }
  if (g.clock_offset_ms != 0.0) {
    c.clock = std::make_shared<runtime::OffsetClock>(runtime::system_clock(), static_cast<std::int64_t>(g.clock_offset_ms * 1e6));
  }
  return c;
}

namespace {
CLI::Validator number_check(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        double v = 0.0;
        try {
          std::size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) throw std::invalid_argument(text);
        } catch (const std::exception&) {
          return "expected a number, got '" + text + "'";
        }
        if (allow_zero ? v < 0.0 : v <= 0.0) return std::string("must be ") + (allow_zero ? ">= 0" : "> 0") + ", got " + text;
        return {};
      },
      allow_zero ? "NUMBER>=0" : "NUMBER>0");
}
}  // namespace

Progress::Progress(bool enabled) : enabled_(enabled), tty_(isatty(fileno(stderr)) != 0) {}

void Progress::operator()(const std::string& text, bool last) {
  if (!enabled_) return;
  if (tty_) {
    const std::size_t pad = shown_.size() > text.size() ? shown_.size() - text.size() : 0;
    std::fprintf(stderr, "\r%s%*s", text.c_str(), static_cast<int>(pad), "");
    shown_ = text;
    if (last) done();
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (!last && logged_ != std::chrono::steady_clock::time_point{} && now - logged_ < std::chrono::seconds(10)) return;
  std::fprintf(stderr, "%s\n", text.c_str());
  logged_ = now;
}

void Progress::done(bool keep) {
  if (!enabled_ || !tty_ || shown_.empty()) return;
  if (keep) std::fprintf(stderr, "\n");
  else std::fprintf(stderr, "\r%*s\r", static_cast<int>(shown_.size()), "");
  shown_.clear();
}

void BadInputs::add(const std::string& message) {
  messages_.push_back(playback::printable(message));
  std::fprintf(stderr, "error: %s\n", messages_.back().c_str());
}

void note_skipped(const playback::Recording& recording) {
  if (const auto s = playback::skipped_summary(recording); !s.empty()) std::fprintf(stderr, "note: %s\n", s.c_str());
}

int BadInputs::exit_code(int rc, std::size_t inputs) const {
  if (messages_.empty()) return rc;
  std::fprintf(stderr, "error: %zu of %zu inputs were bad input (see above); the others were processed\n", messages_.size(), inputs);
  return 2;
}

const CLI::Validator kNonNegative = number_check(true);
const CLI::Validator kPositive = number_check(false);

void add_dds_options(CLI::App& cmd, GlobalOptions& g) {
  cmd.add_option("--domain", g.domain, "DDS domain id (default: $SKELGRAPH_DOMAIN, else 0)")->check(CLI::Range(0, 232));
  cmd.add_option("--profile", g.profile,
                 "DDS profile: loopback (default), lan, or a path to an XML file (env SKELGRAPH_PROFILE)");
  cmd.add_option("--interface", g.interfaces, "restrict UDP to this interface address (repeatable; lan profile)");
  cmd.add_option("--discovery-server", g.discovery_servers,
                 "discover through this server, IP:PORT (repeatable: the i-th is `fastdds discovery -i i`; "
                 "lan-discovery-server profile; env SKELGRAPH_DISCOVERY_SERVERS)");
  cmd.add_option("--security", g.security_dir,
                 "DDS Security credentials from `skelgraph security init` (secure profile; env SKELGRAPH_SECURITY_DIR)");
  cmd.add_option("--clock-offset-ms", g.clock_offset_ms,
                 "run this process on a wall clock this far ahead (negative: behind): plays a host whose clock is off, "
                 "to test clock-offset estimation on one machine");
}

namespace {
struct SignalState {
  std::mutex m;
  std::condition_variable cv;
  int handlers = 0;  // SignalHandling objects alive
  int pending = 0;   // handed over, not yet taken by wait_for_signal
  bool any = false;
};
SignalState& signal_state() {
  static SignalState s;
  return s;
}
sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

void block_signals() {
  const sigset_t set = stop_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread([] {
    const sigset_t watched = stop_signals();
    auto& st = signal_state();
    for (;;) {
      int sig = 0;
      if (sigwait(&watched, &sig) != 0) continue;
      std::lock_guard<std::mutex> lock(st.m);
      const bool again = st.any;  // a second Ctrl-C while the first is being handled: stop now
      st.any = true;
      if (st.handlers == 0 || again) {
        std::fprintf(stderr, "\ninterrupted (%s)\n", sig == SIGINT ? "SIGINT" : "SIGTERM");
        std::fflush(stderr);
        std::_Exit(128 + sig);
      }
      ++st.pending;
      st.cv.notify_all();
    }
  }).detach();
}

bool wait_for_signal(std::chrono::milliseconds timeout) {
  auto& st = signal_state();
  std::unique_lock<std::mutex> lock(st.m);
  if (!st.cv.wait_for(lock, std::max(timeout, std::chrono::milliseconds(0)), [&] { return st.pending > 0; })) return false;
  --st.pending;
  return true;
}

bool interrupted() {
  auto& st = signal_state();
  std::lock_guard<std::mutex> lock(st.m);
  return st.any;
}

SignalHandling::SignalHandling() {
  auto& st = signal_state();
  std::lock_guard<std::mutex> lock(st.m);
  ++st.handlers;
}

SignalHandling::~SignalHandling() {
  auto& st = signal_state();
  std::lock_guard<std::mutex> lock(st.m);
  --st.handlers;
}

namespace {
void setup_logging(const std::string& level) {
  // Logs go to stderr so stdout stays clean for --json output.
  auto logger = spdlog::stderr_color_mt("skelgraph");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  spdlog::set_level(spdlog::level::from_str(level));
  // Fast DDS logs to stdout by default; send its warnings and errors to stderr.
  namespace dl = eprosima::fastdds::dds;
  dl::Log::ClearConsumers();
  dl::Log::RegisterConsumer(std::make_unique<dl::StdoutErrConsumer>());
  dl::Log::SetVerbosity(level == "trace"   ? dl::Log::Kind::Info
                        : level == "debug" ? dl::Log::Kind::Warning
                                           : dl::Log::Kind::Error);
}
}  // namespace

}  // namespace skelgraph::cli

int main(int argc, char** argv) {
  using namespace skelgraph::cli;
  block_signals();
  CLI::App app{"skelgraph: multi-sensor skeleton fusion on DDS. Run a subcommand with --help for its options."};
  GlobalOptions g;
  app.add_option("--log-level", g.log_level, "trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  Action run;
  add_launch_command(app, g, run);
  add_run_command(app, g, run);
  add_play_data_command(app, g, run);
  add_topic_command(app, g, run);
  add_sync_command(app, g, run);
  add_robot_command(app, g, run);
  add_player_command(app, g, run);
  add_security_command(app, g, run);
  add_demo_command(app, g, run);
  add_components_command(app, g, run);
  add_sim_command(app, g, run);
  add_bag_command(app, g, run);
  add_eval_command(app, g, run);
  add_calib_command(app, g, run);
  add_gesture_command(app, g, run);
  add_fuse_command(app, g, run);
  add_depth_command(app, g, run);
#ifdef SKELGRAPH_WITH_OPENNI2
  add_oni_command(app, g, run);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  if (!run) {
    std::fprintf(stderr, "%s\nerror: a subcommand is required\n", app.help().c_str());
    return 2;
  }
  setup_logging(g.log_level);
  int rc = 1;
  try {
    rc = run ? run() : 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "error: %s\n", skelgraph::playback::printable(e.what()).c_str());
    rc = 2;
  } catch (const skelgraph::runtime::LaunchError& e) {
    std::fprintf(stderr, "error: %s\n", skelgraph::playback::printable(e.what()).c_str());
    rc = 2;
  } catch (const skelgraph::playback::DataError& e) {  // a bad input file (file:line: what)
    std::fprintf(stderr, "error: %s\n", e.what());
    rc = 2;
  } catch (const skelgraph::gesture::ModelError& e) {  // a bad model, class map or clip
    std::fprintf(stderr, "error: %s\n", skelgraph::playback::printable(e.what()).c_str());
    rc = 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", skelgraph::playback::printable(e.what()).c_str());
    rc = 1;
  }
  spdlog::shutdown();
  eprosima::fastdds::dds::Log::Flush();
  return rc;
}
