#include "skelgraph/sim/sim_component.hpp"

#include <algorithm>

#include <chrono>
#include <cmath>
#include <sstream>

#include "skelgraph/depth/depth_msg.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::sim {

void add_sim_params(runtime::ParamSchema& schema) {
  schema.add_string("scenario", "walk", "what the people do", scenario_names())
      .add_int("repeats", 1, "times the scenario is performed in a row", 1, 1000)
      .add_int("seed", 1, "random seed: the same seed gives the same run, bit for bit", 0)
      .add_int("people", 1, "people in the cell (the others walk around it)", 1, 8)
      .add_double("height", 1.75, "body height of every person, m", 0.5, 2.5)
      .add_double("work_s", 20.0, "shift: mean time each person works at a place, s", 1.0, 3600.0)
      .add_string("profile", "nite", "tracker model", TrackerProfile::names())
      .add_double("noise_scale", 1.0, "scale of the tracker's random errors (0: none)", 0.0, 10.0)
      .add_int("sensor_count", 2, "sensors of the layout (ignored when 'sensors' is set)", 1, 16)
      .add_string("layout", "quarters",
                  "where the sensors are, 2 m round the cell looking at it: quarters (90 degrees apart, then the 45s), "
                  "ring (evenly), one_side (over the quarter circle in front), corners (4)",
                  layout_names())
      .add_string_list("sensors", {}, "sensor poses 'id:x,y,z,yaw_deg[,pitch_deg]' (yaw 180 looks along -z)")
      .add_double("truth_rate", 30.0, "ground-truth rate, Hz", 1.0, 1000.0)
      .add_double("drop_probability", 0.01, "chance that a sensor frame is lost", 0.0, 0.9)
      .add_double("jitter_ms", 2.0, "sd of sensor frame timing, ms", 0.0, 20.0)
      .add_string("bump", "",
                  "a sensor knocked out of place during the run, SENSOR,AT_S,YAW_DEG,SHIFT_M (turned about the vertical, "
                  "moved to its own left); the poses published stay the calibrated ones (default: none)");
}

SimConfig sim_config_from_assignments(const std::vector<std::string>& assignments, const std::string& what,
                                      const std::vector<runtime::RawParam>& extra) {
  runtime::ParamSchema schema;
  add_sim_params(schema);
  std::vector<runtime::RawParam> raw;
  for (const auto& p : assignments) raw.push_back(runtime::parse_param_assignment(p, "--param " + p));
  raw.insert(raw.end(), extra.begin(), extra.end());
  auto cfg = sim_config_from(schema.resolve(raw, what));
  Simulation probe(cfg);  // checks the configuration
  return cfg;
}

SimConfig sim_config_from(const runtime::Params& params) {
  SimConfig c;
  c.scenario.name = params.get<std::string>("scenario");
  c.scenario.repeats = static_cast<int>(params.get<std::int64_t>("repeats"));
  c.scenario.seed = static_cast<std::uint64_t>(params.get<std::int64_t>("seed"));
  c.scenario.people = static_cast<int>(params.get<std::int64_t>("people"));
  c.scenario.height = params.get<double>("height");
  c.scenario.work_s = params.get<double>("work_s");
  c.profile = params.get<std::string>("profile");
  c.noise_scale = params.get<double>("noise_scale");
  c.truth_rate_hz = params.get<double>("truth_rate");
  const auto specs = runtime::rejoin_named_items(params.get<std::vector<std::string>>("sensors"));
  if (specs.empty()) {
    c.sensors = layout_sensors(params.get<std::string>("layout"), static_cast<int>(params.get<std::int64_t>("sensor_count")));
  } else {
    c.sensors.clear();
    const auto defaults = default_sensors(static_cast<int>(specs.size()));
    for (std::size_t i = 0; i < specs.size(); ++i) c.sensors.push_back(parse_sensor(specs[i], defaults[i]));
  }
  for (auto& s : c.sensors) {
    s.drop_probability = params.get<double>("drop_probability");
    s.jitter_s = params.get<double>("jitter_ms") * 1e-3;
  }
  if (const auto bump = params.get<std::string>("bump"); !bump.empty()) c.bumps.push_back(parse_bump(bump));
  // The first person faces sensor 1.
  c.scenario.facing = Eigen::Vector2d(c.sensors.front().position.x(), c.sensors.front().position.z());
  return c;
}

runtime::ComponentInfo SimComponent::describe() {
  runtime::ComponentInfo info{"sim",
                              "Virtual work cell: ground truth on skelgraph/skeleton/truth, simulated trackers on "
                              "skelgraph/skeleton/raw, true sensor poses on skelgraph/calibration",
                              {}};
  add_sim_params(info.params);
  info.params.add_double("rate", 1.0, "speed: 1 = real time, 2 = twice as fast", 0.01, 100.0)
      .add_bool("loop", false, "run the scenario again at the end (same seed, later clock)")
      .add_string_list("publish_sensors", {}, "publish only these sensors' skeletons and poses (default: all); "
                                              "with wall_clock_aligned, several sims can each play some sensors of one cell")
      .add_bool("publish_truth", true, "publish ground truth")
      .add_bool("publish_raw", true, "publish the simulated trackers' skeletons (off: a depth tracker makes them from the depth images)")
      .add_bool("depth", false, "render each sensor's depth image (people, props, floor, walls) and publish it on skelgraph/depth")
      .add_string("depth_size", "320x240", "depth image size", {"160x120", "320x240", "640x480"})
      .add_bool("depth_noise", true, "Kinect-like depth errors: disparity noise and quantisation, drop-outs, missing edges")
      .add_double("depth_girth", 1.1, "build of the people in the depth images (1: standard capsules; 0.85 slim, 1.25 stout)", 0.5, 2.0)
      .add_bool("publish_poses", true, "publish the sensors' true poses (off: a calibration file or component provides them)")
      .add_bool("robot_hides", true, "a robot's links (skelgraph/robot/state) hide the people behind them from the sensors")
      .add_bool("wall_clock_aligned", false,
                "scenario time = wall clock modulo the scenario's duration, so sims started at different times (or "
                "restarted) agree on where the person is; implies loop");
  return info;
}

SimComponent::SimComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      config_(sim_config_from(params)),
      rate_(params.get<double>("rate")),
      loop_(params.get<bool>("loop") || params.get<bool>("wall_clock_aligned")),
      truth_pub_(ctx, runtime::topics::kSkeletonTruth),
      raw_pub_(ctx, runtime::topics::kSkeletonRaw),
      frame_pub_(ctx, runtime::topics::kSensorFrame),
      pose_pub_(ctx, runtime::topics::kCalibration) {
  sim_ = std::make_unique<Simulation>(config_);  // checks the configuration before the graph starts
  publish_sensors_ = params.get<std::vector<std::string>>("publish_sensors");
  for (const auto& id : publish_sensors_) {
    if (std::none_of(config_.sensors.begin(), config_.sensors.end(), [&](const SensorConfig& c) { return c.id == id; })) {
      throw std::invalid_argument("publish_sensors: no sensor '" + id + "' in this cell");
    }
  }
  publish_truth_ = params.get<bool>("publish_truth");
  publish_raw_ = params.get<bool>("publish_raw");
  if (params.get<bool>("depth")) {
    const auto k = depth::parse_depth_size(params.get<std::string>("depth_size"));
    DepthNoise noise;
    noise.enabled = params.get<bool>("depth_noise");
    girth_ = params.get<double>("depth_girth");
    const Rng base(config_.scenario.seed);
    for (std::size_t i = 0; i < config_.sensors.size(); ++i) {
      renderers_.emplace_back(config_.sensors[i], k, noise);
      depth_rngs_.push_back(base.fork(0xde97000 + i));
    }
    depth_pub_ = std::make_unique<runtime::Publisher<msg::DepthFrame>>(ctx, runtime::topics::kDepth);
  }
  publish_poses_ = params.get<bool>("publish_poses");
  aligned_ = params.get<bool>("wall_clock_aligned");
  if (params.get<bool>("robot_hides")) {
    robot_sub_ = std::make_unique<runtime::Subscription<msg::RobotState>>(
        ctx, runtime::topics::kRobotState, [this](const msg::RobotState& r, const runtime::SampleMeta&) {
          auto& links = robot_links_[r.robot_id().to_string()];
          links.clear();
          for (const auto& c : r.capsules())
            links.push_back({{c.a().x(), c.a().y(), c.a().z()}, {c.b().x(), c.b().y(), c.b().z()}, c.radius()});
          if (sim_) sim_->set_occluders(all_robot_links());
        });
  }
}

std::vector<Capsule> SimComponent::all_robot_links() const {
  std::vector<Capsule> out;
  for (const auto& [id, links] : robot_links_) out.insert(out.end(), links.begin(), links.end());
  return out;
}

bool SimComponent::publishes(std::size_t sensor) const {
  return publish_sensors_.empty() || std::find(publish_sensors_.begin(), publish_sensors_.end(),
                                               config_.sensors[sensor].id) != publish_sensors_.end();
}

void SimComponent::publish_poses() {
  if (!publish_poses_) return;
  for (std::size_t i = 0; i < config_.sensors.size(); ++i) {
    if (!publishes(i)) continue;
    pose_pub_.publish(skeleton::to_msg(config_.sensors[i].true_pose(config_.epoch_ns)));
  }
}

void SimComponent::on_start() {
  start_mono_ns_ = ctx_.clock().monotonic_ns();
  config_.epoch_ns = ctx_.clock().now_ns();
  config_.emit_frames = true;
  config_.emit_departures = true;
  if (aligned_) {
    const auto period = static_cast<std::int64_t>(std::llround(sim_->duration() * 1e9 / rate_));
    const auto into = config_.epoch_ns % period;
    config_.epoch_ns -= into;
    start_mono_ns_ -= into;
    skip_before_s_ = static_cast<double>(into) * 1e-9 * rate_;
  }
  sim_ = std::make_unique<Simulation>(config_);
  sim_->set_occluders(all_robot_links());
  publish_poses();
  timer_ = ctx_.executor().every(std::chrono::milliseconds(5), [this] { tick(); }, true);
}

void SimComponent::tick() {
  const double t = static_cast<double>(ctx_.clock().monotonic_ns() - start_mono_ns_) * 1e-9 * rate_ - loop_offset_s_;
  for (const auto& e : sim_->advance(t)) {
    if (e.t + loop_offset_s_ < skip_before_s_) continue;
    if (e.kind == SimEvent::Kind::Truth) {
      if (!publish_truth_) continue;
      truth_pub_.publish(skeleton::to_msg(e.skeleton));
      ++truth_published_;
    } else if (e.kind == SimEvent::Kind::Left) {
      // The person left the cell: readers of the truth see the instance disposed.
      if (publish_truth_ && truth_pub_.dispose(skeleton::to_msg(e.skeleton))) ++departures_;
    } else if (!publishes(e.sensor)) {
      continue;
    } else if (e.kind == SimEvent::Kind::Lost) {
      // The tracker dropped this user (a new one gets a new id): gone for every reader.
      if (publish_raw_ && raw_pub_.dispose(skeleton::to_msg(e.skeleton))) ++users_lost_;
      continue;
    } else if (e.kind == SimEvent::Kind::Frame) {
      if (publish_raw_) {  // the heartbeat of the raw skeleton stream (a depth tracker sends its own)
        msg::SensorFrame f;
        f.sensor_id(e.skeleton.sensor_id);
        f.stamp_ns(e.skeleton.stamp_ns);
        f.frame_number(e.skeleton.frame_number);
        f.people(e.people);
        frame_pub_.publish(f);
      }
      if (depth_pub_) publish_depth(e);
    } else if (publish_raw_) {
      raw_pub_.publish(skeleton::to_msg(e.skeleton));
      ++raw_published_;
    }
  }
  if (!sim_->finished()) return;
  ++runs_completed_;
  if (loop_) {
    loop_offset_s_ += sim_->duration();
    SimConfig next = config_;
    next.epoch_ns = config_.epoch_ns + std::llround(loop_offset_s_ * 1e9);
    sim_ = std::make_unique<Simulation>(next);
    sim_->set_occluders(all_robot_links());
    return;
  }
  finished_ = true;
  timer_.cancel();
  ctx_.set_health(runtime::HealthState::Ok, "finished");
}

void SimComponent::publish_depth(const SimEvent& frame) {
  const double t = frame.t;  // the frame's capture time on the world clock
  auto image = renderers_[frame.sensor].render(sim_->truth_at(t), sim_->scenario().at(t).obstacles,
                                               depth_rngs_[frame.sensor], config_.scenario.height, girth_);
  image.stamp_ns = frame.skeleton.stamp_ns;
  image.frame_number = frame.skeleton.frame_number;
  depth_pub_->publish(depth::to_msg(std::move(image)));
  ++depth_published_;
}

nlohmann::json SimComponent::details() const {
  nlohmann::json sensors = nlohmann::json::array();
  for (const auto& s : config_.sensors) {
    sensors.push_back({{"id", s.id},
                       {"position", {s.position.x(), s.position.y(), s.position.z()}},
                       {"yaw_deg", s.yaw * 180.0 / M_PI},
                       {"pitch_deg", s.pitch * 180.0 / M_PI},
                       {"clock_offset_ms", s.clock_offset_s * 1e3}});
  }
  return {{"scenario", config_.scenario.name},
          {"seed", config_.scenario.seed},
          {"profile", config_.profile},
          // The tracker model's lag: what fusion's capture_latency_ms should say for these sensors.
          {"capture_latency_ms", TrackerProfile::by_name(config_.profile).lag_s * 1e3},
          {"people", config_.scenario.people},
          {"duration_s", sim_->duration()},
          {"robot_links_hiding", all_robot_links().size()},
          {"sensors", sensors},
          {"truth_published", truth_published_},
          {"raw_published", raw_published_},
          {"depth_published", depth_published_},
          {"runs_completed", runs_completed_},
          {"departures", departures_},
          {"users_lost", users_lost_},
          {"finished", finished_.load()}};
}

std::string SimComponent::summary() const {
  std::ostringstream os;
  os << config_.scenario.name << " (" << config_.profile << ", seed " << config_.scenario.seed << "): "
     << truth_published_ << " truth and " << raw_published_ << " raw skeletons from " << config_.sensors.size()
     << " sensor(s)";
  if (depth_pub_) os << ", " << depth_published_ << " depth images";
  if (departures_ > 0 || users_lost_ > 0) os << ", " << departures_ << " people left, " << users_lost_ << " tracker users lost";
  if (runs_completed_ > 0) os << ", " << runs_completed_ << " run(s) completed";
  return os.str();
}

}  // namespace skelgraph::sim

SKELGRAPH_REGISTER_COMPONENT(sim, skelgraph::sim::SimComponent)
