#include "skelgraph/robot/follow_component.hpp"

#include <chrono>
#include <sstream>

#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::robot {

namespace {
FollowParams follow_params(const runtime::Params& params) {
  FollowParams p;
  p.standoff_m = params.get<double>("standoff_m");
  p.max_age_s = params.get<double>("max_age_ms") * 1e-3;
  const auto lo = parse_point(params.get<std::string>("workspace_min"));
  const auto hi = parse_point(params.get<std::string>("workspace_max"));
  if ((hi - lo).minCoeff() <= 0) throw std::invalid_argument("workspace_max must exceed workspace_min on every axis");
  p.workspace = Eigen::AlignedBox3d(lo, hi);
  const auto side = params.get<std::string>("hand");
  p.joint = side == "left" ? skeleton::JointId::LeftHand : skeleton::JointId::RightHand;
  return p;
}
}  // namespace

runtime::ComponentInfo FollowComponent::describe() {
  runtime::ComponentInfo info{"follow",
                              "The robot's tool follows a worker's hand at a standoff, inside a workspace box (holds "
                              "without a tracked hand or with old data); the separation monitor still decides the speed",
                              {}};
  info.params.add_string("robot_id", "robot1", "the robot commanded")
      .add_string("base", "0,0,1.5,180", "where the robot's base stands: x,y,z (m, world; y up) and yaw (deg)")
      .add_string("hand", "right", "which hand", {"right", "left"})
      .add_double("standoff_m", 0.8, "the tool keeps this far from the hand, on the robot's side", 0.0, 3.0)
      .add_string("workspace_min", "-0.7,0.2,1.0", "the workspace box's low corner x,y,z (world, m)")
      .add_string("workspace_max", "0.7,1.6,1.9", "the workspace box's high corner x,y,z (world, m)")
      .add_double("rate_hz", 20.0, "targets per second", 1.0, 200.0)
      .add_double("speed", 0.5, "tool speed asked, m/s (times the monitor's speed scale)", 0.01, 2.0)
      .add_double("min_move_m", 0.02, "a new target only when it moved this far", 0.0, 1.0)
      .add_double("max_age_ms", 250.0, "fused data older than this: hold", 10.0, 10000.0)
      .add_double("person_timeout_ms", 500.0, "a fused person not heard of this long is dropped", 10.0, 10000.0);
  return info;
}

FollowComponent::FollowComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      robot_id_(params.get<std::string>("robot_id")),
      rate_hz_(params.get<double>("rate_hz")),
      speed_(params.get<double>("speed")),
      min_move_m_(params.get<double>("min_move_m")),
      person_timeout_s_(params.get<double>("person_timeout_ms") * 1e-3),
      follower_(follow_params(params), parse_base(params.get<std::string>("base")).translation()),
      command_pub_(ctx, runtime::topics::kRobotCommand),
      fused_sub_(
          ctx, runtime::topics::kSkeletonFused,
          [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
            people_[m.person_id()] = {skeleton::from_msg(m), meta.receive_ns};
          },
          [this](const msg::Skeleton& last, const runtime::SampleMeta&) { people_.erase(last.person_id()); }) {}

void FollowComponent::on_start() {
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate_hz_)), [this] { step(); });
}

void FollowComponent::command(msg::RobotCommandKind kind, const Eigen::Vector3d& target) {
  if (!command_pub_.publish(command_msg(robot_id_, kind, speed_, target, ctx_.name(), ctx_.clock().now_ns())))
    ++failed_writes_;
}

void FollowComponent::step() {
  const auto now = ctx_.clock().now_ns();
  ++steps_;
  std::vector<skeleton::Skeleton> people;
  for (auto it = people_.begin(); it != people_.end();) {
    if (static_cast<double>(now - it->second.second) * 1e-9 > person_timeout_s_) {
      it = people_.erase(it);
    } else {
      people.push_back(it->second.first);
      ++it;
    }
  }
  const auto t = follower_.step(people, now);
  reason_ = t.reason;
  if (t.hold) {
    if (!sent_once_ || sent_) {
      command(msg::ROBOT_HOLD, Eigen::Vector3d::Zero());
      ++holds_;
    }
    sent_.reset();
  } else {
    ++following_;
    if (!sent_ || (*sent_ - t.target).norm() >= min_move_m_) {
      command(msg::ROBOT_MOVE_TO, t.target);
      ++moves_;
      sent_ = t.target;
    }
  }
  sent_once_ = true;
  if (failed_writes_ > 0) ctx_.set_health(runtime::HealthState::Degraded, "writes failed");
  else ctx_.set_health(runtime::HealthState::Ok, reason_);
}

std::string FollowComponent::summary() const {
  std::ostringstream os;
  os << robot_id_ << ": " << steps_ << " steps, following in " << following_ << ", " << moves_ << " move(s), " << holds_
     << " hold(s)";
  return os.str();
}

nlohmann::json FollowComponent::details() const {
  return {{"robot_id", robot_id_}, {"steps", steps_},  {"following_steps", following_}, {"moves", moves_},
          {"holds", holds_},       {"reason", reason_}, {"failed_writes", failed_writes_}};
}

}  // namespace skelgraph::robot

SKELGRAPH_REGISTER_COMPONENT(follow, skelgraph::robot::FollowComponent)
