#include "skelgraph/fusion/fusion_component.hpp"

#include <sstream>

#include <spdlog/spdlog.h>

#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::fusion {

runtime::ComponentInfo FusionComponent::describe() {
  runtime::ComponentInfo info{"fusion",
                              "Fuses raw skeletons of every sensor into one skeleton per person (world frame) on "
                              "skelgraph/skeleton/fused",
                              {}};
  info.params.add_string("method", "kalman", "how joints are combined", method_names())
      .add_double("rate_hz", 30.0, "output rate when no sync session is ticking", 1.0, 1000.0)
      .add_bool("on_ticks", true, "fuse on every sync TICK while a session runs (instead of the fixed rate)")
      .add_double("max_age_ms", 100.0, "samples older than this are not fused", 1.0, 10000.0)
      .add_double("delay_ms", 0.0, "fuse this far behind now, to interpolate between samples", 0.0, 1000.0)
      .add_double("sensor_timeout_ms", 1000.0, "a sensor silent this long is dropped (status DEGRADED)", 10.0, 60000.0)
      .add_double("person_timeout_ms", 1000.0, "a fused person with no input this long is forgotten", 10.0, 60000.0)
      .add_double("match_distance_m", 0.6, "a sensor's skeleton joins a fused person whose torso is this close", 0.05, 5.0)
      .add_double("predict_ms", 0.0,
                  "kalman: predict each joint this far past the fusion time (the trackers' delay plus the consumer's)",
                  0.0, 1000.0)
      .add_string("output_id", "fused", "sensor_id of the fused skeletons (several fusion components: one each)");
  return info;
}

namespace {
FuserOptions options_from(const runtime::Params& p) {
  FuserOptions o;
  o.method = *method_from_name(p.get<std::string>("method"));
  o.max_age_ns = static_cast<std::int64_t>(p.get<double>("max_age_ms") * 1e6);
  o.delay_ns = static_cast<std::int64_t>(p.get<double>("delay_ms") * 1e6);
  o.sensor_timeout_ns = static_cast<std::int64_t>(p.get<double>("sensor_timeout_ms") * 1e6);
  o.person_timeout_ns = static_cast<std::int64_t>(p.get<double>("person_timeout_ms") * 1e6);
  o.match_distance_m = p.get<double>("match_distance_m");
  o.predict_ns = static_cast<std::int64_t>(p.get<double>("predict_ms") * 1e6);
  return o;
}
}  // namespace

FusionComponent::FusionComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      fuser_(options_from(params)),
      output_id_(params.get<std::string>("output_id")),
      period_ns_(static_cast<std::int64_t>(1e9 / params.get<double>("rate_hz"))),
      on_ticks_(params.get<bool>("on_ticks")),
      out_(ctx, runtime::topics::kSkeletonFused),
      raw_sub_(
          ctx, runtime::topics::kSkeletonRaw,
          [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
            fuser_.add(skeleton::from_msg(m), meta.receive_ns);
          },
          [this](const msg::Skeleton& last, const runtime::SampleMeta&) {
            fuser_.remove(last.sensor_id().to_string(), last.person_id());
          }),
      frame_sub_(ctx, runtime::topics::kSensorFrame,
                 [this](const msg::SensorFrame& f, const runtime::SampleMeta& meta) {
                   fuser_.heartbeat(f.sensor_id().to_string(), meta.receive_ns);
                 }),
      pose_sub_(ctx, runtime::topics::kCalibration,
                [this](const msg::SensorPose& m, const runtime::SampleMeta&) {
                  const auto p = skeleton::from_msg(m);
                  if (p.frame_id != "world") {
                    spdlog::warn("{}: pose of {} is in frame '{}', not 'world': ignored", ctx_.name(), p.sensor_id,
                                 p.frame_id);
                    return;
                  }
                  fuser_.set_pose(p.sensor_id, p.pose);
                }),
      sync_sub_(ctx, runtime::topics::kSync, [this](const msg::SyncCommand& c, const runtime::SampleMeta& meta) {
        if (!on_ticks_ || c.kind() != msg::SYNC_TICK) return;
        last_tick_ns_ = meta.receive_ns;
        ++tick_steps_;
        step(meta.receive_ns);
      }) {}

void FusionComponent::on_start() {
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(period_ns_), [this] {
    const auto now = ctx_.clock().now_ns();
    // Ticks drive the output while they come; the timer takes over when they stop.
    if (on_ticks_ && last_tick_ns_ != 0 && now - last_tick_ns_ < 3 * period_ns_) {
      update_health(now);
      return;
    }
    step(now);
  });
}

void FusionComponent::step(std::int64_t now_ns) {
  ++steps_;
  const auto fused = fuser_.fuse(now_ns);
  // People who left: readers see their instances disposed (and the writer frees them).
  for (const auto id : fuser_.take_departed()) {
    msg::Skeleton key;
    key.sensor_id(output_id_);
    key.person_id(id);
    if (out_.dispose(key)) ++departed_;
  }
  for (auto s : fused) {
    s.sensor_id = output_id_;
    out_.publish(skeleton::to_msg(s));
    ++published_;
  }
  update_health(now_ns);
}

void FusionComponent::update_health(std::int64_t now_ns) {
  const auto silent = fuser_.silent_sensors(now_ns);
  const std::set<std::string> now_silent(silent.begin(), silent.end());
  for (const auto& s : now_silent) {
    if (!silent_.count(s)) {
      ++dropouts_;
      spdlog::warn("{}: sensor {} silent for over {:.0f} ms: fusing without it", ctx_.name(), s,
                   fuser_.options().sensor_timeout_ns * 1e-6);
    }
  }
  for (const auto& s : silent_) {
    if (!now_silent.count(s)) {
      ++rejoins_;
      spdlog::info("{}: sensor {} is back", ctx_.name(), s);
    }
  }
  silent_ = now_silent;
  const auto sensors = fuser_.sensors();
  std::vector<std::string> no_pose;
  for (const auto& s : sensors) {
    if (!fuser_.has_pose(s)) no_pose.push_back(s);
  }
  std::ostringstream msg;
  if (!silent_.empty()) {
    msg << "degraded: fusing " << sensors.size() - silent_.size() << " of " << sensors.size() << " sensors; silent:";
    for (const auto& s : silent_) msg << " " << s;
  }
  if (!no_pose.empty()) {
    msg << (msg.tellp() > 0 ? "; " : "") << "no calibration for:";
    for (const auto& s : no_pose) msg << " " << s;
  }
  if (msg.tellp() > 0) ctx_.set_health(runtime::HealthState::Degraded, msg.str());
  else ctx_.set_health(runtime::HealthState::Ok, "fusing " + std::to_string(sensors.size()) + " sensor(s)");
}

std::string FusionComponent::summary() const {
  std::ostringstream os;
  os << method_name(fuser_.options().method) << ": " << published_ << " fused skeletons in " << steps_ << " steps ("
     << tick_steps_ << " on sync ticks), " << fuser_.sensors().size() << " sensor(s), " << dropouts_ << " dropout(s), "
     << rejoins_ << " rejoin(s), " << departed_ << " person(s) left, " << out_.live_instances() << " in the cell";
  return os.str();
}

nlohmann::json FusionComponent::details() const {
  const auto& st = fuser_.stats();
  return {{"method", method_name(fuser_.options().method)},
          {"steps", steps_},
          {"tick_steps", tick_steps_},
          {"published", published_},
          {"departed", departed_},
          {"people", out_.live_instances()},
          {"streams_ended", st.streams_ended},
          {"sensors", fuser_.sensors()},
          {"silent", std::vector<std::string>(silent_.begin(), silent_.end())},
          {"dropouts", dropouts_},
          {"rejoins", rejoins_},
          {"samples", st.added},
          {"samples_without_pose", st.no_pose},
          {"flips_corrected", st.flips_corrected},
          {"gated", st.gated},
          {"occluded_views", st.occluded_views},
          {"tracks_merged", st.tracks_merged}};
}

}  // namespace skelgraph::fusion

SKELGRAPH_REGISTER_COMPONENT(fusion, skelgraph::fusion::FusionComponent)
