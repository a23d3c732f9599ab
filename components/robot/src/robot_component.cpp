#include "skelgraph/robot/robot_component.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <spdlog/spdlog.h>

#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::robot {

namespace {
std::vector<double> numbers(const std::string& text, std::size_t count, const char* what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v))
      throw std::invalid_argument(std::string(what) + ": '" + item + "' in '" + text + "' is not a number");
    out.push_back(v);
  }
  if (out.size() != count) {
    throw std::invalid_argument(std::string(what) + ": '" + text + "' has " + std::to_string(out.size()) +
                                " numbers, expected " + std::to_string(count));
  }
  return out;
}
void set(msg::Vec3& m, const Eigen::Vector3d& v) {
  m.x(v.x());
  m.y(v.y());
  m.z(v.z());
}
}  // namespace

Eigen::Isometry3d parse_base(const std::string& text) {
  const auto v = numbers(text, 4, "base (x,y,z,yaw_deg)");
  return base_pose(v[0], v[1], v[2], v[3]);
}

Eigen::Vector3d parse_point(const std::string& text) {
  const auto v = numbers(text, 3, "task point (x,y,z)");
  return {v[0], v[1], v[2]};
}

Joints parse_joints_deg(const std::string& text) {
  const auto v = numbers(text, 6, "start_joints_deg (six angles)");
  Joints q;
  for (int i = 0; i < 6; ++i) q(i) = v[static_cast<std::size_t>(i)] * M_PI / 180.0;
  return q;
}

msg::RobotCommand command_msg(const std::string& robot_id, msg::RobotCommandKind kind, double value,
                              const Eigen::Vector3d& target, const std::string& source, std::int64_t stamp_ns) {
  msg::RobotCommand c;
  c.robot_id(robot_id);
  c.kind(kind);
  c.value(value);
  set(c.target(), target);
  c.source(source);
  c.stamp_ns(stamp_ns);
  return c;
}

msg::RobotState state_msg(const std::string& robot_id, const ArmSim& arm, std::int64_t stamp_ns) {
  msg::RobotState s;
  s.robot_id(robot_id);
  s.model(arm.model().name);
  s.stamp_ns(stamp_ns);
  for (int i = 0; i < 6; ++i) {
    s.joints()[static_cast<std::size_t>(i)] = arm.joints()(i);
    s.joint_speeds()[static_cast<std::size_t>(i)] = arm.joint_speeds()(i);
  }
  set(s.tool_position(), arm.tool_world());
  s.tool_speed(arm.tool_speed());
  s.speed_scale(arm.speed_scale());
  s.protective_stop(arm.stopped());
  s.has_target(arm.has_target());
  for (const auto& c : arm.capsules()) {
    msg::Capsule m;
    set(m.a(), c.a);
    set(m.b(), c.b);
    m.radius(c.radius);
    m.name(c.name);
    s.capsules().push_back(m);
  }
  return s;
}

runtime::ComponentInfo RobotComponent::describe() {
  runtime::ComponentInfo info{"robot",
                              "A simulated 6-axis arm (UR5e kinematics) in the cell: its state on skelgraph/robot/state, "
                              "requests on skelgraph/robot/command",
                              {}};
  info.params.add_string("robot_id", "robot1", "the robot's id (key of its state; commands for it or for '')")
      .add_string("model", "ur5e", "arm model", {"ur5e"})
      .add_string("base", "0,0,1.5,180", "where its base stands: x,y,z (m, world; y up) and yaw (deg about the vertical)")
      .add_string("start_joints_deg", "0,-90,90,-90,-90,0", "joint angles at start, degrees")
      .add_double("rate_hz", 100.0, "control and state rate", 1.0, 1000.0)
      .add_string_list("task", {}, "a task of its own: the tool round these points 'x,y,z' (world, m), until a command takes over")
      .add_double("task_speed", 0.5, "the task's tool speed, m/s (times the speed scale)", 0.01, 1.0)
      .add_string_list("accept_from", {"separation", "follow", "fetch", "operator"},
                       "sources whose commands it takes (the commanding component's name; `skelgraph robot` sends "
                       "as 'operator'); others are refused and counted")
      .add_double("max_command_age_s", 1.0,
                  "a command stamped longer ago than this (or this far ahead: a clock off) is refused", 0.01, 60.0);
  return info;
}

RobotComponent::RobotComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      id_(params.get<std::string>("robot_id")),
      arm_(ArmModel::ur5e(), parse_base(params.get<std::string>("base")),
           parse_joints_deg(params.get<std::string>("start_joints_deg"))),
      rate_hz_(params.get<double>("rate_hz")),
      task_speed_(params.get<double>("task_speed")),
      gate_{params.get<std::vector<std::string>>("accept_from"), params.get<double>("max_command_age_s")},
      state_pub_(ctx, runtime::topics::kRobotState),
      command_sub_(ctx, runtime::topics::kRobotCommand,
                   [this](const msg::RobotCommand& c, const runtime::SampleMeta&) { on_command(c); }) {
  // From a launch file each item is "x,y,z"; from a command line (-p task=...) the list arrives split at every comma.
  auto items = params.get<std::vector<std::string>>("task");
  if (!items.empty() && std::none_of(items.begin(), items.end(), [](const std::string& i) { return i.find(',') != std::string::npos; })) {
    if (items.size() % 3 != 0) throw std::invalid_argument("task: " + std::to_string(items.size()) + " numbers, not x,y,z triples");
    std::vector<std::string> joined;
    for (std::size_t i = 0; i < items.size(); i += 3) joined.push_back(items[i] + "," + items[i + 1] + "," + items[i + 2]);
    items = joined;
  }
  for (const auto& p : items) task_.push_back(parse_point(p));
  task_active_ = !task_.empty();
}

void RobotComponent::on_start() {
  last_mono_ns_ = ctx_.clock().monotonic_ns();
  ctx_.set_health(runtime::HealthState::Ok, "running");
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate_hz_)), [this] { step(); },
                                 true);
}

void RobotComponent::on_command(const msg::RobotCommand& c) {
  if (c.robot_id().size() > 0 && c.robot_id().to_string() != id_) {
    ++ignored_;
    return;
  }
  const auto verdict = check_command(gate_, c.source().to_string(), c.stamp_ns(), ctx_.clock().now_ns());
  if (!verdict.ok) {
    ++(verdict.stale ? refused_stale_ : refused_source_);
    if (last_refusal_ != verdict.reason) spdlog::warn("{}: refused {}", ctx_.name(), verdict.reason);
    last_refusal_ = verdict.reason;
    return;
  }
  ++commands_;
  const Eigen::Vector3d target(c.target().x(), c.target().y(), c.target().z());
  switch (c.kind()) {
    case msg::ROBOT_MOVE_TO:
      task_active_ = false;
      arm_.set_target(target, c.value() > 0 ? c.value() : 0.25);
      break;
    case msg::ROBOT_HOLD:
      task_active_ = false;
      arm_.clear_target();
      break;
    case msg::ROBOT_SPEED_SCALE: arm_.set_speed_scale(c.value()); break;
    case msg::ROBOT_PROTECTIVE_STOP:
      if (!arm_.stopped()) {
        ++stops_;
        spdlog::warn("{}: protective stop asked by {}", ctx_.name(), c.source().to_string());
      }
      arm_.protective_stop();
      break;
    case msg::ROBOT_RESUME: arm_.resume(); break;
  }
}

void RobotComponent::step() {
  const auto now = ctx_.clock().monotonic_ns();
  const double dt = std::min(0.1, static_cast<double>(now - last_mono_ns_) * 1e-9);
  last_mono_ns_ = now;
  if (task_active_) {
    if ((arm_.tool_world() - task_[task_next_]).norm() < 0.01) {
      task_next_ = (task_next_ + 1) % task_.size();
      ++task_points_reached_;
    }
    arm_.set_target(task_[task_next_], task_speed_);
  }
  arm_.step(dt);
  ++steps_;
  const bool sent = state_pub_.publish(state_msg(id_, arm_, ctx_.clock().now_ns()));
  ++(sent ? published_ : failed_publish_);
  std::string message = arm_.stopped() ? "protective stop" : "running";
  if (refused_source_ + refused_stale_ > 0)
    message += "; refused " + std::to_string(refused_source_) + " command(s) from unknown sources, " +
               std::to_string(refused_stale_) + " stale (last: " + last_refusal_ + ")";
  if (!sent) {
    ctx_.set_health(runtime::HealthState::Degraded, "its state could not be written; " + message);
  } else {
    ctx_.set_health(runtime::HealthState::Ok, message);
  }
}

std::string RobotComponent::summary() const {
  std::ostringstream os;
  os << id_ << " (" << arm_.model().name << "): " << published_ << " states, " << commands_ << " commands, " << stops_
     << " protective stop(s)";
  if (refused_source_ + refused_stale_ > 0)
    os << ", refused " << refused_source_ << " command(s) from unknown sources and " << refused_stale_ << " stale";
  return os.str();
}

nlohmann::json RobotComponent::details() const {
  const auto t = arm_.tool_world();
  return {{"robot_id", id_},   {"model", arm_.model().name}, {"steps", steps_},         {"published", published_},
          {"commands", commands_}, {"ignored", ignored_},     {"protective_stops", stops_},
          {"refused_source", refused_source_}, {"refused_stale", refused_stale_}, {"last_refusal", last_refusal_},
          {"failed_publish", failed_publish_},
          {"stopped", arm_.stopped()}, {"speed_scale", arm_.speed_scale()}, {"tool", {t.x(), t.y(), t.z()}},
          {"task_points_reached", task_points_reached_}};
}

}  // namespace skelgraph::robot

SKELGRAPH_REGISTER_COMPONENT(robot, skelgraph::robot::RobotComponent)
