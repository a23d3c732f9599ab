#include "skelgraph/gesture/gesture_component.hpp"

#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::gesture {

namespace {

const runtime::TopicDef<msg::Skeleton>& input_topic(const std::string& name) {
  if (name == "raw") return runtime::topics::kSkeletonRaw;
  if (name == "truth") return runtime::topics::kSkeletonTruth;
  return runtime::topics::kSkeletonFused;
}

Classifier load_model(const std::string& path, const std::string& who) {
  if (path.empty())
    throw std::invalid_argument("model: no classifier given (a file from `skelgraph gesture train` or `gesture sim --out`, or 'sim')");
  const bool builtin = is_builtin_model(path);
  auto c = builtin ? load_builtin_model(path) : Classifier::load(path);
  if (builtin) spdlog::info("{}: built-in model '{}' ({})", who, path, builtin_model_path(path).string());
  if (needs_wrists(c.feature_set()))
    throw std::invalid_argument("model: " + path + " uses the '" + feature_set_name(c.feature_set()) +
                                "' features, which need wrist joints; the skeleton topics carry none (train with thesis8, extended or body)");
  return c;
}

msg::Vec3 vec(const Eigen::Vector3d& v) {
  msg::Vec3 m;
  m.x(v.x());
  m.y(v.y());
  m.z(v.z());
  return m;
}

}  // namespace

runtime::ComponentInfo GestureComponent::describe() {
  runtime::ComponentInfo info{"gesture",
                              "Spots gestures (pointing first) in a skeleton stream; publishes skelgraph/gesture/event with "
                              "the pointing ray and its target, and each person's state on skelgraph/gesture/state",
                              {}};
  info.params.add_string("model", "", "classifier file (skelgraph gesture train / gesture sim --out), or 'sim': the built-in pointing model (trained on simulated sessions by the build)")
      .add_string("input", "fused", "skeleton stream to watch", {"fused", "raw", "truth"})
      .add_string("point_label", "point", "the classifier's label for pointing")
      .add_string_list("held_labels", {"stop"}, "other gestures made by holding an arm out: reported once held hold_s, "
                                                "not when the arm comes down")
      .add_string_list("surfaces", {"floor:0,0,0"},
                       "where pointing rays may land: 'name:x,y,z' (horizontal plane through the point) or "
                       "'name:x,y,z:nx,ny,nz'; the nearest hit wins")
      .add_double("hold_s", 0.25, "an extended arm held still this long is tried as pointing", 0.0, 5.0)
      .add_double("aim_s", 1.5,
                  "the pointing ray is averaged over the hold for up to this long; the event goes out when the arm moves "
                  "again or then (at most hold_s: at once)",
                  0.0, 10.0)
      .add_double("still_speed", 0.25, "a hand slower than this is still, m/s", 0.01, 5.0)
      .add_double("min_raise_deg", 35.0, "an extended arm counts as pointing only raised this far from hanging straight down", 0.0, 180.0)
      .add_double("max_target_m", 4.0, "pointing must land on a surface within this of the shoulder (0: any ray)", 0.0, 100.0)
      .add_bool("other_arm_free", true, "pointing needs the other arm not held out as well (carrying, a stretch)")
      .add_double("confirm_s", -1.0,
                  "pointing must stay held this long after hold_s or it is dropped (a confirmation; -1: the model's operating point)",
                  -1.0, 10.0)
      .add_double("min_confidence", -1.0,
                  "events less sure than this (1 - exp(-margin) over the next class) are dropped (-1: the model's operating point)",
                  -1.0, 1.0)
      .add_double("min_straightness", 0.90, "pointing: shoulder to hand over the arm's length, averaged over the hold, at least this (0: any)", 0.0, 1.0)
      .add_double("max_lean_m", 0.07, "pointing: the neck at most this far off the torso horizontally over the hold, m (0: any)", 0.0, 1.0)
      .add_double("person_timeout_ms", 2000.0, "a person not seen this long is forgotten", 10.0, 60000.0);
  return info;
}

namespace {
SpotterOptions spotter_options(const runtime::Params& params) {
  SpotterOptions o;
  o.point_label = params.get<std::string>("point_label");
  o.held_labels = params.get<std::vector<std::string>>("held_labels");
  o.hold = params.get<double>("hold_s");
  o.aim = params.get<double>("aim_s");
  o.still_speed = params.get<double>("still_speed");
  o.min_raise = params.get<double>("min_raise_deg");
  o.max_target = params.get<double>("max_target_m");
  o.other_arm_free = params.get<bool>("other_arm_free");
  o.confirm = params.get<double>("confirm_s");
  o.min_confidence = params.get<double>("min_confidence");
  o.min_straightness = params.get<double>("min_straightness");
  o.max_lean_m = params.get<double>("max_lean_m");
  o.surfaces.clear();
  for (const auto& s : runtime::rejoin_named_items(params.get<std::vector<std::string>>("surfaces"))) o.surfaces.push_back(parse_surface(s));
  return o;
}
}  // namespace

GestureComponent::GestureComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      options_(spotter_options(params)),
      classifier_(load_model(params.get<std::string>("model"), ctx.name())),
      person_timeout_ns_(static_cast<std::int64_t>(params.get<double>("person_timeout_ms") * 1e6)),
      event_pub_(ctx, runtime::topics::kGestureEvent),
      state_pub_(ctx, runtime::topics::kGestureState),
      sub_(
          ctx, input_topic(params.get<std::string>("input")),
          [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) { on_skeleton(skeleton::from_msg(m), meta.receive_ns); },
          [this](const msg::Skeleton& last, const runtime::SampleMeta&) {
            // The person left (the writer disposed them): forgotten at once.
            const auto it = people_.find({last.sensor_id().to_string(), last.person_id()});
            if (it != people_.end()) forget(it);
          }) {
  // The operating point the model was given, unless the parameters set one.
  if (options_.min_confidence < 0) options_.min_confidence = classifier_.operating_point().min_confidence;
  if (options_.confirm < 0) options_.confirm = classifier_.operating_point().confirm_s;
  const auto& labels = classifier_.labels();
  if (std::find(labels.begin(), labels.end(), options_.point_label) == labels.end())
    spdlog::warn("{}: the classifier has no class '{}': no pointing rays will be given", ctx_.name(), options_.point_label);
}

void GestureComponent::on_start() {
  timer_ = ctx_.executor().every(std::chrono::seconds(1), [this] {
    const auto now = ctx_.clock().now_ns();
    for (auto it = people_.begin(); it != people_.end();) {
      if (now - it->second.last_seen_ns > person_timeout_ns_) {
        it = forget(it);
        continue;
      }
      publish_state(it->first.first, it->first.second, it->second);
      ++it;
    }
    ctx_.set_health(runtime::HealthState::Ok, std::to_string(people_.size()) + " person(s) watched, " +
                                                  std::to_string(events_) + " gesture(s)");
  });
}

GestureComponent::People::iterator GestureComponent::forget(People::iterator it) {
  msg::GestureState key;
  key.person_id(it->first.second);
  key.source(it->first.first);
  state_pub_.dispose(key);
  ++left_;
  return people_.erase(it);
}

void GestureComponent::publish_state(const std::string& source, std::uint32_t person, const Person& p) {
  msg::GestureState m;
  m.person_id(person);
  m.source(source);
  m.stamp_ns(p.last_stamp_ns);
  m.state(motion_state_name(p.spotter->state()));
  state_pub_.publish(m);
}

void GestureComponent::on_skeleton(const skeleton::Skeleton& s, std::int64_t receive_ns) {
  ++skeletons_;
  auto& p = people_[{s.sensor_id, s.person_id}];
  if (!p.spotter) {
    p.spotter = std::make_unique<Spotter>(classifier_, options_);
    ++seen_;
  }
  if (s.stamp_ns <= p.last_stamp_ns) return;  // out of order or repeated
  p.last_seen_ns = receive_ns;
  p.last_stamp_ns = s.stamp_ns;
  for (const auto& e : p.spotter->step(s)) {
    msg::GestureEvent m;
    m.label(e.label);
    m.person_id(e.person_id);
    m.source(s.sensor_id);
    m.start_stamp_ns(e.start_ns);
    m.end_stamp_ns(e.end_ns);
    m.score(-std::log(std::max(1e-12, 1.0 - e.confidence)));
    m.log_likelihood(e.log_likelihood);
    m.confidence(e.confidence);
    m.arm(e.arm);
    m.has_ray(e.has_ray);
    m.ray_origin(vec(e.ray_origin));
    m.ray_direction(vec(e.ray_direction));
    m.has_target(e.has_target);
    m.target(vec(e.target));
    m.target_name(e.target_name);
    event_pub_.publish(m);
    ++events_;
    ++events_by_label_[e.label];
    if (e.has_target) {
      spdlog::info("{}: {} by person {} ({} arm) at {} ({:.2f}, {:.2f}, {:.2f}) m, confidence {:.2f}", ctx_.name(), e.label,
                   e.person_id, e.arm, e.target_name, e.target.x(), e.target.y(), e.target.z(), e.confidence);
    } else {
      spdlog::info("{}: {} by person {}{}, confidence {:.2f}", ctx_.name(), e.label, e.person_id,
                   e.has_ray ? " (the ray meets no surface)" : "", e.confidence);
    }
  }
  if (!p.ever_published || p.spotter->state() != p.published) {
    p.published = p.spotter->state();
    p.ever_published = true;
    publish_state(s.sensor_id, s.person_id, p);
  }
}

std::string GestureComponent::summary() const {
  std::ostringstream os;
  os << events_ << " gesture(s) in " << skeletons_ << " skeletons of " << seen_ << " person(s) (" << left_ << " left)";
  for (const auto& [label, n] : events_by_label_) os << ", " << label << " " << n;
  return os.str();
}

nlohmann::json GestureComponent::details() const {
  return {{"skeletons", skeletons_},
          {"events", events_},
          {"by_label", events_by_label_},
          {"people", people_.size()},
          {"people_seen", seen_},
          {"people_left", left_},
          {"operating_point", {{"min_confidence", options_.min_confidence}, {"confirm_s", options_.confirm}}}};
}

}  // namespace skelgraph::gesture

SKELGRAPH_REGISTER_COMPONENT(gesture, skelgraph::gesture::GestureComponent)
