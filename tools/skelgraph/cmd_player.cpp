// skelgraph player pause|resume|step|speed|state: drives the running players of
// recordings (the openni2 component on an .oni file) over skelgraph/play/control
// and prints their state from skelgraph/play/state.

#include <unistd.h>

#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>
#include <random>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/msg/json.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::cli {

namespace {

struct PlayerOpts {
  std::string target;  // "" every player
  double timeout = 5.0;
  bool json = false;
  double value = 0.0;
};

std::string describe(const msg::PlayState& s) {
  std::string text = s.player().to_string() + ": " + (s.at_end() ? "at the end" : s.paused() ? "paused" : "playing") +
                     ", speed " + nlohmann::json(s.speed()).dump() + ", frame " + std::to_string(s.frames());
  if (s.frame_count() >= 0) text += " of " + std::to_string(s.frame_count());
  if (s.position_s() >= 0) {
    char pos[64];
    std::snprintf(pos, sizeof(pos), ", at %.2f s", s.position_s());
    text += pos;
    if (s.duration_s() >= 0) {
      std::snprintf(pos, sizeof(pos), " of %.2f s", s.duration_s());
      text += pos;
    }
  }
  if (s.error().size() > 0) text += "; refused: " + s.error().to_string();
  return text;
}

// Sends the request (repeated each second until answered: the control topic is
// volatile and players handle each request id once) and prints the answers:
// the target's, or every player's answer within half a second of the first.
// `kind` empty: only prints the players' latest states.
int request(const runtime::DdsConfig& config, std::optional<msg::PlayKind> kind, const PlayerOpts& o) {
  const auto timeout = std::chrono::milliseconds(static_cast<std::int64_t>(o.timeout * 1000));
  const std::string me = "skelgraph_player_cli_" + std::to_string(::getpid());
  std::mt19937_64 rng(std::random_device{}());
  const std::string request_id = me + "_" + std::to_string(rng());

  runtime::Context ctx(me, config);
  std::mutex mutex;
  std::condition_variable cv;
  std::map<std::string, msg::PlayState> answers;
  runtime::Publisher<msg::PlayControl> control(ctx, runtime::topics::kPlayControl);
  runtime::Subscription<msg::PlayState> state(ctx, runtime::topics::kPlayState, [&](const msg::PlayState& s,
                                                                                     const runtime::SampleMeta&) {
    if (!o.target.empty() && s.player().to_string() != o.target) return;
    if (kind && s.request_id().to_string() != request_id) return;
    std::lock_guard<std::mutex> lock(mutex);
    answers[s.player().to_string()] = s;
    cv.notify_all();
  });
  ctx.executor().start();
  const std::string who = o.target.empty() ? "no player of recordings" : "no player named '" + o.target + "'";
  const std::string where = " found on domain " + std::to_string(config.domain) + " (profile " + config.profile +
                            ") within " + nlohmann::json(o.timeout).dump() + " s";
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock<std::mutex> lock(mutex);
  if (!kind) {
    if (!cv.wait_until(lock, deadline, [&] { return !answers.empty(); })) throw std::runtime_error(who + where);
    // The other players' states, and the rest of the kept history (late joiners get it oldest first).
    cv.wait_for(lock, std::chrono::milliseconds(500), [] { return false; });
  } else {
    lock.unlock();
    if (!control.wait_for_matched(1, timeout)) throw std::runtime_error(who + where);
    msg::PlayControl c;
    c.target(o.target.substr(0, 64));
    c.kind(*kind);
    c.value(o.value);
    c.request_id(request_id.substr(0, 64));
    lock.lock();
    while (answers.empty() && std::chrono::steady_clock::now() < deadline) {
      lock.unlock();
      control.publish(c);
      lock.lock();
      cv.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() + std::chrono::seconds(1)),
                    [&] { return !answers.empty(); });
    }
    if (answers.empty()) throw std::runtime_error(who + " answered within " + nlohmann::json(o.timeout).dump() + " s");
    if (o.target.empty()) cv.wait_for(lock, std::chrono::milliseconds(500), [] { return false; });
  }
  int rc = 0;
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [name, s] : answers) {
    if (s.error().size() > 0) rc = 1;
    if (o.json) {
      out.push_back(s);
    } else {
      std::printf("%s\n", describe(s).c_str());
    }
  }
  if (o.json) std::printf("%s\n", out.dump().c_str());
  return rc;
}

}  // namespace

void add_player_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto o = std::make_shared<PlayerOpts>();
  auto* cmd = app.add_subcommand(
      "player", "Pause, resume, step, speed up or seek the running players of recordings (openni2 on an .oni file, bag play)");
  cmd->require_subcommand(1);
  auto* pause = cmd->add_subcommand("pause", "Pause: no frame until resume or step");
  auto* resume = cmd->add_subcommand("resume", "Play on at the player's speed, paced from now");
  auto* step = cmd->add_subcommand("step", "Deliver the next frames now and pause (answers once they are out)");
  step->add_option("--frames", o->value, "how many frames")->default_val(1.0)->check(CLI::Range(1.0, 1e6));
  auto* speed = cmd->add_subcommand("speed", "A new speed, paced from the next frame");
  speed->add_option("SPEED", o->value, "1 real time, 2 twice as fast, 0 as fast as frames can be read")
      ->required()
      ->check(CLI::Range(0.0, 1000.0));
  auto* seek = cmd->add_subcommand("seek", "Go to a position in the recording (players that can seek: bag_player)");
  seek->add_option("SECONDS", o->value, "seconds from the start of the recording")->required()->check(CLI::Range(0.0, 1e7));
  auto* st = cmd->add_subcommand("state", "Print the players' state");
  for (auto* c : {pause, resume, step, speed, seek, st}) {
    c->add_option("--target", o->target, "the player's component name (default: every player)");
    c->add_option("--timeout", o->timeout, "seconds to wait for the players")->check(kPositive);
    c->add_flag("--json", o->json, "the players' states as a JSON array");
    add_dds_options(*c, g);
  }
  const auto bind = [o, &g, &run](CLI::App* c, std::optional<msg::PlayKind> kind) {
    c->callback([o, &g, &run, kind] { run = [o, &g, kind] { return request(make_config(g), kind, *o); }; });
  };
  bind(pause, msg::PLAY_PAUSE);
  bind(resume, msg::PLAY_RESUME);
  bind(step, msg::PLAY_STEP);
  bind(speed, msg::PLAY_SPEED);
  bind(seek, msg::PLAY_SEEK);
  bind(st, std::nullopt);
}

}  // namespace skelgraph::cli
