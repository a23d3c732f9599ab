#include "skelgraph/robot/fetch_component.hpp"

#include <sstream>

#include <spdlog/spdlog.h>

#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::robot {

runtime::ComponentInfo FetchComponent::describe() {
  runtime::ComponentInfo info{"fetch",
                              "Pointing to fetch: a pointed floor target the robot reaches, while its monitor says RUN, "
                              "sends the tool to hover above it",
                              {}};
  info.params.add_string("robot_id", "robot1", "the robot commanded")
      .add_string("base", "0,0,1.5,180", "where the robot's base stands: x,y,z (m, world; y up) and yaw (deg)")
      .add_string("label", "point", "the gesture events' label for pointing")
      .add_double("hover_m", 0.15, "the tool this far above the target", 0.0, 1.0)
      .add_double("min_reach_m", 0.25, "targets closer to the base (horizontally) are its own footprint", 0.0, 2.0)
      .add_double("max_reach_m", 0.8, "targets farther from the base are out of reach", 0.1, 3.0)
      .add_double("speed", 0.25, "tool speed asked, m/s (times the monitor's speed scale)", 0.01, 2.0)
      .add_double("max_verdict_age_ms", 500.0, "the monitor's verdict must be this fresh", 10.0, 10000.0)
      .add_bool("allow_reduced", false, "also fetch while the monitor says REDUCED (it still sets the speed)");
  return info;
}

FetchComponent::FetchComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      robot_id_(params.get<std::string>("robot_id")),
      label_(params.get<std::string>("label")),
      base_(parse_base(params.get<std::string>("base")).translation()),
      speed_(params.get<double>("speed")),
      max_verdict_age_ns_(static_cast<std::int64_t>(params.get<double>("max_verdict_age_ms") * 1e6)),
      allow_reduced_(params.get<bool>("allow_reduced")),
      command_pub_(ctx, runtime::topics::kRobotCommand),
      safety_sub_(ctx, runtime::topics::kSafety,
                  [this](const msg::SafetyStatus& s, const runtime::SampleMeta& meta) {
                    if (s.robot_id().to_string() != robot_id_) return;
                    verdict_ = s;
                    verdict_ns_ = meta.receive_ns;
                  }),
      gesture_sub_(ctx, runtime::topics::kGestureEvent,
                   [this](const msg::GestureEvent& e, const runtime::SampleMeta&) { on_event(e); }) {
  params_.hover_m = params.get<double>("hover_m");
  params_.min_reach_m = params.get<double>("min_reach_m");
  params_.max_reach_m = params.get<double>("max_reach_m");
  ctx_.set_health(runtime::HealthState::Ok, "waiting for pointing");
}

void FetchComponent::on_event(const msg::GestureEvent& e) {
  if (e.label().to_string() != label_ || !e.has_target()) return;
  ++events_;
  const Eigen::Vector3d spot(e.target().x(), e.target().y(), e.target().z());
  std::ostringstream why;
  const auto target = fetch_target(spot, base_, params_);
  const auto now = ctx_.clock().now_ns();
  if (!target) {
    ++out_of_reach_;
    why << "person " << e.person_id() << " pointed out of reach";
  } else if (!verdict_ || now - verdict_ns_ > max_verdict_age_ns_ ||
             !(verdict_->state() == msg::SAFETY_RUN || (allow_reduced_ && verdict_->state() == msg::SAFETY_REDUCED))) {
    ++not_run_;
    why << "person " << e.person_id() << " pointed in reach, but the monitor does not say " << (allow_reduced_ ? "RUN or REDUCED" : "RUN");
  } else if (sent_ && (*sent_ - *target).norm() < 0.05) {
    ++repeats_;
    return;
  } else {
    if (command_pub_.publish(command_msg(robot_id_, msg::ROBOT_MOVE_TO, speed_, *target, ctx_.name(), now))) {
      ++sent_count_;
      sent_ = target;
    } else {
      ++failed_writes_;
    }
    why << "fetching for person " << e.person_id() << " at (" << target->x() << ", " << target->z() << ")";
    spdlog::info("{}: {}", ctx_.name(), why.str());
  }
  last_ = why.str();
  if (failed_writes_ > 0) ctx_.set_health(runtime::HealthState::Degraded, "writes failed");
  else ctx_.set_health(runtime::HealthState::Ok, last_);
}

std::string FetchComponent::summary() const {
  std::ostringstream os;
  os << robot_id_ << ": " << events_ << " pointing events, " << sent_count_ << " fetch(es) sent, " << out_of_reach_
     << " out of reach, " << not_run_ << " while not RUN";
  return os.str();
}

nlohmann::json FetchComponent::details() const {
  nlohmann::json d = {{"robot_id", robot_id_}, {"events", events_},     {"sent", sent_count_},
                      {"repeats", repeats_},   {"out_of_reach", out_of_reach_}, {"not_run", not_run_},
                      {"failed_writes", failed_writes_}, {"last", last_}};
  if (sent_) d["target"] = {sent_->x(), sent_->y(), sent_->z()};
  return d;
}

}  // namespace skelgraph::robot

SKELGRAPH_REGISTER_COMPONENT(fetch, skelgraph::robot::FetchComponent)
