// skelgraph robot stop|resume|hold|speed S|move X,Y,Z: one command to a robot
// on skelgraph/robot/command, as an operator would send it (source
// 'operator'), confirmed by the robot's own state (skelgraph/robot/state):
// exit 0 only when the state shows it taken. Whether the robot obeys is its
// own decision (its status says when it refuses one).

#include <unistd.h>

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::cli {

namespace {

struct RobotOpts {
  std::string robot_id, source = "operator", target;
  double value = 0, speed = 0.25, timeout = 10;
  bool json = false;
};

// Whether a robot's state shows the command taken (every command is idempotent).
bool shows(const msg::RobotState& s, msg::RobotCommandKind kind, double value, const Eigen::Vector3d& target) {
  switch (kind) {
    case msg::ROBOT_PROTECTIVE_STOP: return s.protective_stop();
    case msg::ROBOT_RESUME: return !s.protective_stop();
    case msg::ROBOT_HOLD: return !s.has_target();
    case msg::ROBOT_SPEED_SCALE: return std::abs(s.speed_scale() - value) < 1e-6;
    case msg::ROBOT_MOVE_TO:
      return s.has_target() &&
             (Eigen::Vector3d(s.target().x(), s.target().y(), s.target().z()) - target).norm() < 1e-6;
  }
  return false;
}

int send(const runtime::DdsConfig& config, const std::string& name, msg::RobotCommandKind kind, const RobotOpts& o) {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double value = o.value;
  if (kind == msg::ROBOT_MOVE_TO) {
    try {
      target = robot::parse_point(o.target);
    } catch (const std::exception& e) {
      throw UsageError(std::string("move: ") + e.what());
    }
    value = o.speed;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<std::int64_t>(o.timeout * 1000));
  runtime::Context ctx("skelgraph_robot_cli_" + std::to_string(::getpid()), config);
  std::mutex mutex;
  std::condition_variable cv;
  std::optional<msg::RobotState> state;  // the newest state of the robot (of any, without --robot-id)
  runtime::Subscription<msg::RobotState> states(ctx, runtime::topics::kRobotState,
                                                [&](const msg::RobotState& s, const runtime::SampleMeta&) {
                                                  if (!o.robot_id.empty() && s.robot_id().to_string() != o.robot_id) return;
                                                  std::lock_guard<std::mutex> lock(mutex);
                                                  state = s;
                                                  cv.notify_all();
                                                });
  runtime::Publisher<msg::RobotCommand> pub(ctx, runtime::topics::kRobotCommand);
  ctx.executor().start();
  const std::string robot = o.robot_id.empty() ? "a robot" : "robot '" + o.robot_id + "'";
  {
    // The robot is there (its state reaches us: our participants know each other).
    std::unique_lock<std::mutex> lock(mutex);
    if (!cv.wait_until(lock, deadline, [&] { return state.has_value(); }))
      throw std::runtime_error("no state of " + robot + " on " + runtime::topics::kRobotState.name + " (domain " +
                               std::to_string(config.domain) + ", profile " + config.profile + ") within " +
                               nlohmann::json(o.timeout).dump() + " s: nothing sent");
  }
  // Sent again each second until the robot's state shows it taken (its command
  // reader may match us a moment after its state did; every command is idempotent).
  int sent = 0;
  bool taken = false;
  while (!taken && std::chrono::steady_clock::now() < deadline) {
    if (pub.publish(robot::command_msg(o.robot_id, kind, value, target, o.source, ctx.clock().now_ns()))) ++sent;
    std::unique_lock<std::mutex> lock(mutex);
    taken = cv.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() + std::chrono::seconds(1)),
                          [&] { return shows(*state, kind, value, target); });
  }
  const nlohmann::json out = {{"command", name}, {"robot_id", o.robot_id}, {"source", o.source},
                              {"sent", sent},    {"taken", taken}};
  if (o.json) {
    std::printf("%s\n", out.dump().c_str());
  } else if (taken) {
    std::printf("%s: taken by %s (its state shows it; sent %d time(s) as '%s')\n", name.c_str(), robot.c_str(), sent,
                o.source.c_str());
  } else {
    std::fprintf(stderr,
                 "%s: sent %d time(s) as '%s', but the state of %s does not show it within %s s (its status says "
                 "whether it refused the source or the stamp)\n",
                 name.c_str(), sent, o.source.c_str(), robot.c_str(), nlohmann::json(o.timeout).dump().c_str());
  }
  return taken ? 0 : 1;
}

}  // namespace

void add_robot_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto o = std::make_shared<RobotOpts>();
  auto* robot = app.add_subcommand("robot", "Send a robot one command (protective stop, resume, hold, speed scale, move)");
  robot->require_subcommand(1);
  const std::vector<std::tuple<std::string, msg::RobotCommandKind, std::string>> kinds = {
      {"stop", msg::ROBOT_PROTECTIVE_STOP, "protective stop"},
      {"resume", msg::ROBOT_RESUME, "resume after a protective stop"},
      {"hold", msg::ROBOT_HOLD, "stay where it is (ends its task or a move)"},
      {"speed", msg::ROBOT_SPEED_SCALE, "scale its speed (0..1)"},
      {"move", msg::ROBOT_MOVE_TO, "move the tool to X,Y,Z (world, m)"}};
  for (const auto& [name, kind, what] : kinds) {
    auto* c = robot->add_subcommand(name, what);
    if (kind == msg::ROBOT_SPEED_SCALE) c->add_option("SCALE", o->value, "speed scale")->required()->check(CLI::Range(0.0, 1.0));
    if (kind == msg::ROBOT_MOVE_TO) {
      c->add_option("TARGET", o->target, "x,y,z in the world frame, m")->required();
      c->add_option("--speed", o->speed, "tool speed, m/s")->check(kPositive);
    }
    c->add_option("--robot-id", o->robot_id, "the robot (default: every robot)");
    c->add_option("--source", o->source, "who asks, as the robot's accept_from knows it (default: operator)");
    c->add_option("--timeout", o->timeout, "seconds to wait for the robot to show the command taken")->check(kPositive);
    c->add_flag("--json", o->json, "what was sent and whether it was taken, as JSON");
    add_dds_options(*c, g);
    c->callback([o, &g, &run, name = name, kind = kind] { run = [o, &g, name, kind] { return send(make_config(g), name, kind, *o); }; });
  }
}

}  // namespace skelgraph::cli
