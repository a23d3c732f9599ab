// skelgraph sync start|stop [--label L]: asks the running sync master to start
// or stop a session and waits until it confirms on skelgraph/sync/session.

#include <unistd.h>

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <random>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/msg/json.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::cli {

namespace {

int request(const runtime::DdsConfig& config, msg::SyncKind kind, const std::string& label, double timeout_s,
            bool json) {
  const auto timeout = std::chrono::milliseconds(static_cast<std::int64_t>(timeout_s * 1000));
  const std::string me = "skelgraph_sync_cli_" + std::to_string(::getpid());
  std::mt19937_64 rng(std::random_device{}());
  const std::string request_id = me + "_" + std::to_string(rng());

  runtime::Context ctx(me, config);
  std::mutex mutex;
  std::condition_variable cv;
  std::optional<msg::SyncCommand> answer;
  runtime::Publisher<msg::SyncControl> control(ctx, runtime::topics::kSyncControl);
  runtime::Subscription<msg::SyncCommand> session(
      ctx, runtime::topics::kSyncSession, [&](const msg::SyncCommand& c, const runtime::SampleMeta&) {
        // Only our answer: a START also stops the previous session first, with the same request id.
        if (c.request_id().to_string() != request_id || c.kind() != kind) return;
        std::lock_guard<std::mutex> lock(mutex);
        answer = c;
        cv.notify_all();
      });
  ctx.executor().start();
  if (!control.wait_for_matched(1, timeout)) {
    throw std::runtime_error("no sync master found on domain " + std::to_string(config.domain) + " (profile " +
                             config.profile + ") within " + std::to_string(timeout_s) + " s");
  }
  session.wait_for_matched(1, timeout);
  msg::SyncControl c;
  c.kind(kind);
  c.label(label.substr(0, 128));
  c.requester(me.substr(0, 64));
  c.request_id(request_id.substr(0, 64));
  // The control topic is volatile and other readers (a recorder) may have
  // matched our writer before the master did, so the request is repeated every
  // second until answered; the master handles each request id once.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock<std::mutex> lock(mutex);
  while (!answer.has_value() && std::chrono::steady_clock::now() < deadline) {
    lock.unlock();
    control.publish(c);
    lock.lock();
    cv.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() + std::chrono::seconds(1)),
                  [&] { return answer.has_value(); });
  }
  if (!answer.has_value()) {
    if (kind == msg::SYNC_STOP) {
      std::fprintf(stderr, "no session was running (the sync master did not answer the STOP within %.1f s)\n",
                   timeout_s);
      return 1;
    }
    throw std::runtime_error("the sync master did not confirm within " + std::to_string(timeout_s) + " s");
  }
  if (json) {
    std::printf("%s\n", nlohmann::json(*answer).dump().c_str());
  } else {
    std::printf("%s session %u '%s'%s\n", msg::to_string(answer->kind()), answer->session_id(),
                answer->label().c_str(),
                answer->kind() == msg::SYNC_STOP ? (" after " + std::to_string(answer->tick()) + " ticks").c_str() : "");
  }
  return 0;
}

}  // namespace

void add_sync_command(CLI::App& app, GlobalOptions& g, Action& run) {
  struct Opts {
    std::string label = "session";
    double timeout = 5.0;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sync = app.add_subcommand("sync", "Start or stop a recording session on the running sync master");
  sync->require_subcommand(1);
  auto* start = sync->add_subcommand("start", "Start a session (a running one is stopped first)");
  start->add_option("--label", o->label, "session label (recordings are named after it)");
  auto* stop = sync->add_subcommand("stop", "Stop the running session");
  for (auto* c : {start, stop}) {
    c->add_option("--timeout", o->timeout, "seconds to wait for the sync master")->check(kPositive);
    c->add_flag("--json", o->json, "print the confirming START/STOP as JSON");
    add_dds_options(*c, g);
  }
  start->callback([o, &g, &run] {
    run = [o, &g] { return request(make_config(g), msg::SYNC_START, o->label, o->timeout, o->json); };
  });
  stop->callback([o, &g, &run] {
    run = [o, &g] { return request(make_config(g), msg::SYNC_STOP, "", o->timeout, o->json); };
  });
}

}  // namespace skelgraph::cli
