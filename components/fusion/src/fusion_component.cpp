#include "skelgraph/fusion/fusion_component.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
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
      .add_string("trigger", "ticks",
                  "when to fuse: ticks (every sync TICK while a session runs, else at rate_hz), timer (at rate_hz), "
                  "arrival (as soon as every live sensor has delivered its frame, or arrival_wait_ms after the first)",
                  {"ticks", "timer", "arrival"})
      .add_double("arrival_wait_ms", 30.0, "arrival: the longest wait for the other sensors' frames after the first",
                  0.0, 1000.0)
      .add_double("max_age_ms", 100.0, "samples older than this are not fused", 1.0, 10000.0)
      .add_double("delay_ms", 0.0, "fuse this far behind now, to interpolate between samples", 0.0, 1000.0)
      .add_double("sensor_timeout_ms", 1000.0, "a sensor silent this long is dropped (status DEGRADED)", 10.0, 60000.0)
      .add_double("person_timeout_ms", 1000.0, "a fused person with no input this long is forgotten", 10.0, 60000.0)
      .add_double("match_distance_m", 0.6, "a sensor's skeleton joins a fused person whose torso is this close", 0.05, 5.0)
      .add_double("predict_ms", 0.0,
                  "kalman: predict each joint this far past the fusion time (the trackers' delay plus the consumer's)",
                  0.0, 1000.0)
      .add_string_list("capture_latency_ms", {},
                       "the trackers' own delay, 'SENSOR:MS' or 'MS' for every sensor (NITE: about 50): the fused "
                       "skeletons' capture stamps say when the body was where they show it")
      .add_double("bias_sd_scale", 1.0,
                  "kalman, weighted: scale of the trackers' joint-placement error added to the published covariance "
                  "(1: as fitted on the simulator's NITE model; 0: the filter's and the sensors' part alone)",
                  0.0, 10.0)
      .add_string("sensor_clocks", "estimate",
                  "estimate: each sensor's clock is brought onto this host's by its quickest delivery; shared: the "
                  "sensors stamp on this host's clock (same host, or PTP), so a tracker's processing time counts in "
                  "the age",
                  {"estimate", "shared"})
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
  o.shared_clock = p.get<std::string>("sensor_clocks") == "shared";
  o.bias_sd_scale = p.get<double>("bias_sd_scale");
  return o;
}

// capture_latency_ms entries: "SENSOR:MS" for one sensor, "MS" for every other.
std::map<std::string, std::int64_t> latencies_from(const runtime::Params& p) {
  std::map<std::string, std::int64_t> out;
  for (const auto& item : p.get<std::vector<std::string>>("capture_latency_ms")) {
    const auto colon = item.rfind(':');
    const auto number = colon == std::string::npos ? item : item.substr(colon + 1);
    std::size_t used = 0;
    double ms = -1;
    try {
      ms = std::stod(number, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != number.size() || number.empty() || ms < 0 || ms > 10000) {
      throw std::invalid_argument("capture_latency_ms: '" + item +
                                  "' is not 'SENSOR:MS' or 'MS' with MS a number of milliseconds in [0, 10000]");
    }
    out[colon == std::string::npos ? std::string() : item.substr(0, colon)] = std::llround(ms * 1e6);
  }
  return out;
}

// The fuser with its options and each sensor's capture latency (the list parsed once).
Fuser make_fuser(const runtime::Params& p) {
  auto o = options_from(p);
  const auto latencies = latencies_from(p);
  if (latencies.count("")) o.capture_latency_ns = latencies.at("");
  Fuser f(o);
  for (const auto& [sensor, ns] : latencies) {
    if (!sensor.empty()) f.set_capture_latency(sensor, ns);
  }
  return f;
}
}  // namespace

FusionComponent::FusionComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      fuser_(make_fuser(params)),
      output_id_(params.get<std::string>("output_id")),
      period_ns_(static_cast<std::int64_t>(1e9 / params.get<double>("rate_hz"))),
      trigger_(params.get<std::string>("trigger")),
      gate_(static_cast<std::int64_t>(params.get<double>("arrival_wait_ms") * 1e6)),
      out_(ctx, runtime::topics::kSkeletonFused),
      raw_sub_(
          ctx, runtime::topics::kSkeletonRaw,
          [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
            fuser_.add(skeleton::from_msg(m), meta.receive_ns);
            if (trigger_ != "arrival") return;
            gate_.skeleton(m.sensor_id().to_string(), m.frame_number(), meta.receive_ns);
            fuse_if_ready(meta.receive_ns);
          },
          [this](const msg::Skeleton& last, const runtime::SampleMeta&) {
            fuser_.remove(last.sensor_id().to_string(), last.person_id());
          }),
      frame_sub_(ctx, runtime::topics::kSensorFrame,
                 [this](const msg::SensorFrame& f, const runtime::SampleMeta& meta) {
                   fuser_.heartbeat(f.sensor_id().to_string(), meta.receive_ns);
                   if (trigger_ != "arrival") return;
                   gate_.frame(f.sensor_id().to_string(), f.frame_number(), f.people(), meta.receive_ns);
                   fuse_if_ready(meta.receive_ns);
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
        if (trigger_ != "ticks" || c.kind() != msg::SYNC_TICK) return;
        last_tick_ns_ = meta.receive_ns;
        ++tick_steps_;
        step(meta.receive_ns);
      }) {}

void FusionComponent::on_start() {
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(period_ns_), [this] {
    const auto now = ctx_.clock().now_ns();
    // Ticks (or arrivals) drive the output while they come; the timer takes over when they stop.
    const bool driven = (trigger_ == "ticks" && last_tick_ns_ != 0 && now - last_tick_ns_ < 3 * period_ns_) ||
                        (trigger_ == "arrival" && last_step_ns_ != 0 && now - last_step_ns_ < 3 * period_ns_);
    if (driven) {
      update_health(now);
      return;
    }
    step(now);
  });
}

// Arrival: every live sensor (heard lately, calibrated) has delivered its
// frame, or the wait for the rest ran out: fuse now. Else, the first time
// something new is waiting, a one-shot timer ends the wait.
void FusionComponent::fuse_if_ready(std::int64_t now_ns) {
  now_ns = std::max(now_ns, ctx_.clock().now_ns());
  std::vector<std::string> live;
  const auto silent = fuser_.silent_sensors(now_ns);
  for (const auto& s : fuser_.sensors()) {
    if (fuser_.has_pose(s) && std::find(silent.begin(), silent.end(), s) == silent.end()) live.push_back(s);
  }
  const auto why = gate_.ready(live, now_ns);
  if (why == ArrivalGate::Ready::NotYet) {
    const auto deadline = gate_.deadline();
    if (deadline && !wait_armed_) {
      wait_armed_ = true;
      wait_timer_ = ctx_.executor().every(std::chrono::nanoseconds(std::max<std::int64_t>(*deadline - now_ns, 100'000)),
                                          [this] {
                                            wait_armed_ = false;
                                            wait_timer_.cancel();
                                            fuse_if_ready(ctx_.clock().now_ns());
                                          });
    }
    return;
  }
  if (wait_armed_) {
    wait_armed_ = false;
    wait_timer_.cancel();
  }
  step(now_ns);
  gate_.fused(why);
}

void FusionComponent::step(std::int64_t now_ns) {
  ++steps_;
  last_step_ns_ = now_ns;
  const auto t0 = std::chrono::steady_clock::now();
  const auto fused = fuser_.fuse(now_ns);
  compute_.add(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
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
     << tick_steps_ << " on sync ticks, " << gate_.counts().all_arrived << " on every sensor's arrival, "
     << gate_.counts().waited_out << " after the arrival wait), " << fuser_.sensors().size() << " sensor(s), " << dropouts_ << " dropout(s), "
     << rejoins_ << " rejoin(s), " << departed_ << " person(s) left, " << out_.live_instances() << " in the cell";
  return os.str();
}

nlohmann::json FusionComponent::details() const {
  const auto& st = fuser_.stats();
  return {{"method", method_name(fuser_.options().method)},
          {"steps", steps_},
          {"tick_steps", tick_steps_},
          {"trigger", trigger_},
          {"arrival_steps", gate_.counts().all_arrived},
          {"arrival_waited_out", gate_.counts().waited_out},
          {"compute_us", compute_.json()},
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
          {"ghost_views", st.ghost_views},
          {"tracks_merged", st.tracks_merged}};
}

}  // namespace skelgraph::fusion

SKELGRAPH_REGISTER_COMPONENT(fusion, skelgraph::fusion::FusionComponent)
