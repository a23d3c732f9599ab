#include "skelgraph/robot/separation_component.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <spdlog/spdlog.h>

#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::robot {

namespace {
msg::SafetyStateKind to_msg(SafetyState s) {
  switch (s) {
    case SafetyState::Run: return msg::SAFETY_RUN;
    case SafetyState::Reduced: return msg::SAFETY_REDUCED;
    case SafetyState::ProtectiveStop: return msg::SAFETY_PROTECTIVE_STOP;
  }
  return msg::SAFETY_PROTECTIVE_STOP;
}
Eigen::Vector3d vec(const msg::Vec3& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

runtime::ComponentInfo SeparationComponent::describe() {
  runtime::ComponentInfo info{"separation",
                              "Speed-and-separation monitoring of a robot (ISO/TS 15066 formula; not a certified safety "
                              "function): fused skeletons and the robot's state in, RUN / REDUCED / PROTECTIVE_STOP on "
                              "skelgraph/safety and as commands to the robot",
                              {}};
  info.params.add_string("robot_id", "robot1", "the robot watched and commanded")
      .add_double("rate_hz", 100.0, "decisions per second", 1.0, 1000.0)
      .add_double("robot_max_speed", 0.5, "the tool speed the application asks of the robot, m/s", 0.01, 5.0)
      .add_double("command_latency_ms", 10.0, "from a decision to the robot acting on it (added to the reaction time)",
                  0.0, 1000.0)
      .add_double("margin_m", 0.3, "full speed only with this much room beyond S_p", 0.0, 5.0)
      .add_double("max_people_age_ms", 250.0, "older people data: protective stop", 10.0, 10000.0)
      .add_double("max_robot_age_ms", 100.0, "older robot state: protective stop", 10.0, 10000.0)
      .add_double("person_timeout_ms", 500.0, "a fused person not heard of this long is dropped", 10.0, 10000.0)
      .add_double("sensor_timeout_ms", 500.0, "a sensor without a frame this long is lost", 10.0, 10000.0)
      .add_double("release_ms", 500.0, "after a stop, the way must be clear this long before the robot moves again",
                  0.0, 10000.0)
      .add_int("min_sensors", 1, "fewer live sensors than this: protective stop (coverage lost)", 0, 64)
      .add_string("stop_label", "stop",
                  "a gesture event with this label (skelgraph/gesture/event) stops the robot (\"\": gestures never do)")
      .add_double("gesture_stop_s", 5.0, "a stop gesture holds the robot this long (then release_ms as after any stop)",
                  0.1, 600.0);
  return info;
}

SeparationComponent::SeparationComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      robot_id_(params.get<std::string>("robot_id")),
      rate_hz_(params.get<double>("rate_hz")),
      robot_max_speed_(params.get<double>("robot_max_speed")),
      command_latency_s_(params.get<double>("command_latency_ms") * 1e-3),
      person_timeout_s_(params.get<double>("person_timeout_ms") * 1e-3),
      sensor_timeout_s_(params.get<double>("sensor_timeout_ms") * 1e-3),
      min_sensors_(static_cast<int>(params.get<std::int64_t>("min_sensors"))),
      latch_(params.get<double>("release_ms") * 1e-3),
      safety_pub_(ctx, runtime::topics::kSafety),
      command_pub_(ctx, runtime::topics::kRobotCommand),
      stop_label_(params.get<std::string>("stop_label")),
      gesture_stop_s_(params.get<double>("gesture_stop_s")),
      fused_sub_(
          ctx, runtime::topics::kSkeletonFused,
          [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
            people_[m.person_id()] = {skeleton::from_msg(m), meta.receive_ns};
          },
          [this](const msg::Skeleton& last, const runtime::SampleMeta&) { people_.erase(last.person_id()); }),
      robot_sub_(ctx, runtime::topics::kRobotState,
                 [this](const msg::RobotState& s, const runtime::SampleMeta& meta) {
                   if (s.robot_id().to_string() != robot_id_) return;
                   robot_ = s;
                   have_robot_ = true;
                   robot_received_ns_ = meta.receive_ns;
                 }),
      frame_sub_(ctx, runtime::topics::kSensorFrame,
                 [this](const msg::SensorFrame& f, const runtime::SampleMeta& meta) {
                   sensor_seen_ns_[f.sensor_id().to_string()] = meta.receive_ns;
                 }),
      gesture_sub_(ctx, runtime::topics::kGestureEvent,
                   [this](const msg::GestureEvent& e, const runtime::SampleMeta&) {
                     if (stop_label_.empty() || e.label().to_string() != stop_label_) return;
                     ++stop_gestures_;
                     gesture_stop_until_ns_ = ctx_.clock().now_ns() + static_cast<std::int64_t>(gesture_stop_s_ * 1e9);
                     gesture_stop_reason_ = "stop gesture by person " + std::to_string(e.person_id()) + " (" +
                                            e.source().to_string() + ")";
                     spdlog::warn("{}: {}", ctx_.name(), gesture_stop_reason_);
                   }) {
  params_.margin_m = params.get<double>("margin_m");
  params_.max_people_age_s = params.get<double>("max_people_age_ms") * 1e-3;
  params_.max_robot_age_s = params.get<double>("max_robot_age_ms") * 1e-3;
}

void SeparationComponent::on_start() {
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate_hz_)), [this] { step(); });
}

void SeparationComponent::command(msg::RobotCommandKind kind, double value) {
  if (command_pub_.publish(command_msg(robot_id_, kind, value, Eigen::Vector3d::Zero(), ctx_.name(), ctx_.clock().now_ns())))
    ++commands_;
  else ++failed_writes_;
}

void SeparationComponent::step() {
  const auto t0 = std::chrono::steady_clock::now();
  const auto now = ctx_.clock().now_ns();
  ++steps_;
  for (auto it = people_.begin(); it != people_.end();) {
    if (static_cast<double>(now - it->second.received_ns) * 1e-9 > person_timeout_s_) it = people_.erase(it);
    else ++it;
  }
  int live = 0;
  std::int64_t newest_frame = std::numeric_limits<std::int64_t>::min();
  for (const auto& [id, t] : sensor_seen_ns_) {
    newest_frame = std::max(newest_frame, t);
    if (static_cast<double>(now - t) * 1e-9 <= sensor_timeout_s_) ++live;
  }
  SeparationInput in;
  in.coverage_lost = live < min_sensors_;
  in.robot_age_s = have_robot_ ? static_cast<double>(now - robot_received_ns_) * 1e-9
                              : std::numeric_limits<double>::infinity();
  in.robot_speed = have_robot_ ? robot_.tool_speed() : 0.0;
  in.robot_max_speed = robot_max_speed_;
  std::vector<Capsule> robot_caps;
  if (have_robot_) {
    for (const auto& c : robot_.capsules()) robot_caps.push_back({vec(c.a()), vec(c.b()), c.radius(), c.name().to_string()});
  }
  // The closest person part to the robot, and how old that person's data is.
  in.separation_m = std::numeric_limits<double>::infinity();
  std::uint32_t who = 0;
  std::string body, robot_part;
  // Nobody there: "nobody" is as old as the last sensor frame; else the
  // oldest person's capture decides (fused skeletons may come before the
  // first sensor frame is heard).
  double people_age = newest_frame == std::numeric_limits<std::int64_t>::min()
                          ? std::numeric_limits<double>::infinity()
                          : static_cast<double>(now - newest_frame) * 1e-9;
  if (!people_.empty()) people_age = 0;
  for (const auto& [id, p] : people_) {
    if (!skeleton::centre_of(p.s)) {
      in.unplaced_person = true;
      continue;
    }
    const auto c = separation_to(p.s, robot_caps);
    const std::int64_t capture = p.s.capture_newest_ns != 0 ? p.s.capture_newest_ns : p.s.stamp_ns;
    if (c.distance < in.separation_m) {
      in.separation_m = c.distance;
      in.person_uncertainty_m = c.uncertainty_m;
      who = id;
      body = c.part;
      robot_part = c.robot_part;
    }
    people_age = std::max(people_age, static_cast<double>(now - capture) * 1e-9);  // the oldest person decides
  }
  if (std::isfinite(in.separation_m)) {
    std::ostringstream os;
    os << "person " << who << " " << body << " / " << robot_part;
    in.closest = os.str();
  }
  in.people_age_s = people_age;
  in.reaction_s = people_age + last_compute_s_ + command_latency_s_;
  if (now < gesture_stop_until_ns_) in.stop_gesture = gesture_stop_reason_;
  const auto d = latch_.apply(decide(params_, stopping_, in), static_cast<double>(now) * 1e-9);
  last_compute_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (std::isfinite(in.reaction_s)) reaction_ms_.add(in.reaction_s * 1e3);
  ++time_in_[safety_state_name(d.state)];
  // Commands on change: stop; from a stop, the speed then resume; a new speed.
  const bool was_stop = published_once_ && last_.state == SafetyState::ProtectiveStop;
  if (d.state == SafetyState::ProtectiveStop && (!published_once_ || !was_stop)) {
    command(msg::ROBOT_PROTECTIVE_STOP, 0);
    ++stops_;
    spdlog::warn("{}: protective stop: {}", ctx_.name(), d.reason);
  } else if (d.state != SafetyState::ProtectiveStop) {
    if (!published_once_ || was_stop || std::abs(d.speed_scale - last_.speed_scale) > 0.02) {
      command(msg::ROBOT_SPEED_SCALE, d.speed_scale);
    }
    if (!published_once_ || was_stop) command(msg::ROBOT_RESUME, 0);
  }
  const bool changed = !published_once_ || d.state != last_.state || std::abs(d.speed_scale - last_.speed_scale) > 0.02;
  if (changed || now - last_publish_ns_ >= 100'000'000) {
    msg::SafetyStatus s;
    s.robot_id(robot_id_);
    s.stamp_ns(now);
    s.state(to_msg(d.state));
    s.speed_scale(d.speed_scale);
    s.separation_m(std::isfinite(in.separation_m) ? in.separation_m : -1.0);
    s.protective_m(d.protective_m);
    s.person_id(who);
    s.body_part(body.substr(0, 32));
    s.robot_part(robot_part.substr(0, 32));
    s.people_age_ms(std::isfinite(people_age) ? people_age * 1e3 : -1.0);  // -1: none yet
    s.reaction_ms(std::isfinite(in.reaction_s) ? in.reaction_s * 1e3 : -1.0);
    s.reason(d.reason.substr(0, 256));
    if (!safety_pub_.publish(s)) ++failed_writes_;
    last_publish_ns_ = now;
  }
  last_ = d;
  published_once_ = true;
  if (failed_writes_ > 0) ctx_.set_health(runtime::HealthState::Degraded, "writes failed");
  else ctx_.set_health(runtime::HealthState::Ok, std::string(safety_state_name(d.state)) + ": " + d.reason);
}

std::string SeparationComponent::summary() const {
  std::ostringstream os;
  os << robot_id_ << ": " << steps_ << " decisions (";
  bool first = true;
  for (const auto& [state, n] : time_in_) {
    os << (first ? "" : ", ") << state << " " << n;
    first = false;
  }
  os << "), " << stops_ << " protective stop(s), " << commands_ << " commands";
  return os.str();
}

nlohmann::json SeparationComponent::details() const {
  return {{"robot_id", robot_id_},     {"steps", steps_},           {"steps_by_state", time_in_},
          {"protective_stops", stops_}, {"commands", commands_},     {"failed_writes", failed_writes_},
          {"stop_gestures", stop_gestures_},
          {"state", safety_state_name(last_.state)}, {"reason", last_.reason},
          {"reaction_ms", reaction_ms_.json()}};
}

}  // namespace skelgraph::robot

SKELGRAPH_REGISTER_COMPONENT(separation, skelgraph::robot::SeparationComponent)
