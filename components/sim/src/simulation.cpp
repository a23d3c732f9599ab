#include "skelgraph/sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace skelgraph::sim {

struct Simulation::SensorState {
  SensorConfig config;
  std::vector<double> times;
  std::size_t next = 0;
  std::uint32_t next_user_id = 1;
  std::uint64_t frame = 0;
  std::vector<std::unique_ptr<TrackerModel>> trackers;  // one per place (Actor::slot)
  std::vector<std::uint32_t> reported;                  // per tracker: the user it reported last frame (0 none)
  bool bumped = false;                                  // SimConfig::bumps applied
};

Simulation::Simulation(SimConfig config)
    : cfg_(std::move(config)), scenario_(cfg_.scenario), body_(BodyDimensions::from_height(cfg_.scenario.height)) {
  if (cfg_.sensors.empty()) throw std::invalid_argument("the simulation needs at least one sensor");
  if (!(cfg_.truth_rate_hz > 0.0 && cfg_.truth_rate_hz <= 1000.0)) throw std::invalid_argument("truth rate must be 0-1000 Hz");
  if (!(cfg_.noise_scale >= 0.0 && cfg_.noise_scale <= 10.0)) throw std::invalid_argument("noise scale must be 0-10");
  const auto& profile = TrackerProfile::by_name(cfg_.profile);
  const Rng root(cfg_.scenario.seed);
  for (std::size_t i = 0; i < cfg_.sensors.size(); ++i) {
    const auto& sc = cfg_.sensors[i];
    for (std::size_t k = 0; k < i; ++k) {
      if (cfg_.sensors[k].id == sc.id) throw std::invalid_argument("two sensors named '" + sc.id + "'");
    }
    if (!(sc.rate_hz > 0.0 && sc.rate_hz <= 1000.0)) throw std::invalid_argument("sensor '" + sc.id + "': bad rate");
    auto st = std::make_unique<SensorState>();
    st->config = sc;
    Rng timing = root.fork(1000 + i);
    st->times = frame_times(sc, scenario_.duration(), timing);
    for (int p = 0; p < cfg_.scenario.people; ++p) {
      st->trackers.push_back(std::make_unique<TrackerModel>(profile, sc, root.fork(2000 + 100 * i + p),
                                                            cfg_.noise_scale, cfg_.scenario.height / 1.75,
                                                            &st->next_user_id));
    }
    st->reported.assign(st->trackers.size(), 0);
    sensors_.push_back(std::move(st));
  }
  for (const auto& b : cfg_.bumps) {
    if (std::none_of(cfg_.sensors.begin(), cfg_.sensors.end(), [&](const SensorConfig& c) { return c.id == b.sensor; })) {
      throw std::invalid_argument("bump: no sensor '" + b.sensor + "' in this cell");
    }
  }
}

Simulation::~Simulation() = default;

std::vector<skeleton::Skeleton> Simulation::truth_at(double t) const {
  const Scene scene = scenario_.at(t);
  std::vector<skeleton::Skeleton> out;
  for (const auto& a : scene.actors) {
    auto s = forward_kinematics(body_, a.pose);
    s.sensor_id = "truth";
    s.person_id = a.person_id;
    s.stamp_ns = cfg_.epoch_ns + std::llround(t * 1e9);
    out.push_back(std::move(s));
  }
  return out;
}

std::size_t Simulation::frame_count(std::size_t sensor) const { return sensors_.at(sensor)->times.size(); }

bool Simulation::finished() const {
  const double next_truth = static_cast<double>(truth_frame_) / cfg_.truth_rate_hz;
  if (next_truth < scenario_.duration()) return false;
  for (const auto& s : sensors_) {
    if (s->next < s->times.size()) return false;
  }
  return true;
}

void Simulation::emit_truth(double t, std::vector<SimEvent>& out) {
  auto truths = truth_at(t);
  if (cfg_.emit_departures) {
    std::vector<std::uint32_t> present;
    for (const auto& s : truths) present.push_back(s.person_id);
    for (const auto id : truth_present_) {
      if (std::find(present.begin(), present.end(), id) != present.end()) continue;
      SimEvent e;
      e.kind = SimEvent::Kind::Left;
      e.t = t;
      e.actor = id;
      e.skeleton.sensor_id = "truth";
      e.skeleton.person_id = id;
      e.skeleton.stamp_ns = cfg_.epoch_ns + std::llround(t * 1e9);
      out.push_back(std::move(e));
    }
    truth_present_ = std::move(present);
  }
  for (auto& s : truths) {
    SimEvent e;
    e.kind = SimEvent::Kind::Truth;
    e.t = t;
    e.actor = s.person_id;
    s.frame_number = truth_frame_;
    e.skeleton = std::move(s);
    out.push_back(std::move(e));
  }
}

SimConfig::Bump parse_bump(const std::string& spec) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("bump '" + spec + "': " + why + " (expected SENSOR,AT_S,YAW_DEG,SHIFT_M, e.g. sensor2,60,3,0)");
  };
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (;;) {
    const auto comma = spec.find(',', from);
    parts.push_back(spec.substr(from, comma == std::string::npos ? std::string::npos : comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  if (parts.size() != 4) throw bad(std::to_string(parts.size()) + " fields");
  if (parts[0].empty()) throw bad("no sensor");
  SimConfig::Bump b;
  b.sensor = parts[0];
  double* fields[] = {&b.at_s, &b.yaw_deg, &b.shift_m};
  for (int k = 0; k < 3; ++k) {
    std::size_t used = 0;
    try {
      *fields[k] = std::stod(parts[k + 1], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != parts[k + 1].size() || !std::isfinite(*fields[k])) throw bad("'" + parts[k + 1] + "' is not a number");
  }
  if (b.at_s < 0) throw bad("the time is negative");
  return b;
}

void Simulation::emit_raw(std::size_t i, double t, std::vector<SimEvent>& out) {
  auto& st = *sensors_[i];
  for (const auto& b : cfg_.bumps) {
    if (b.sensor != st.config.id || t < b.at_s || st.bumped) continue;
    // Knocked: turned about the vertical through it, moved to its own left.
    st.bumped = true;
    SensorConfig moved = st.config;
    moved.yaw += b.yaw_deg * M_PI / 180.0;
    moved.position += b.shift_m * (st.config.world_from_sensor().linear() * Eigen::Vector3d::UnitX());
    for (auto& tracker : st.trackers) tracker->move_sensor(moved);
  }
  Scene scene = scenario_.at(t);
  scene.occluders = occluders_;
  std::vector<skeleton::Skeleton> truths;
  for (const auto& a : scene.actors) truths.push_back(forward_kinematics(body_, a.pose));
  ++st.frame;
  std::uint32_t people = 0;
  for (std::size_t p = 0; p < st.trackers.size(); ++p) {
    // The person at this tracker's place, if anyone is there now.
    std::size_t actor = 0;
    while (actor < scene.actors.size() && scene.actors[actor].slot != p) ++actor;
    auto s = st.trackers[p]->observe(t, scene, actor, truths);
    const std::uint32_t user = s ? s->person_id : 0;
    if (cfg_.emit_departures && st.reported[p] != 0 && st.reported[p] != user) {
      SimEvent e;
      e.kind = SimEvent::Kind::Lost;
      e.t = t;
      e.sensor = i;
      e.skeleton.sensor_id = st.config.id;
      e.skeleton.frame_id = st.config.id;
      e.skeleton.person_id = st.reported[p];
      e.skeleton.stamp_ns = sensor_stamp_ns(st.config, t, cfg_.epoch_ns);
      out.push_back(std::move(e));
    }
    st.reported[p] = user;
    if (!s) continue;
    ++people;
    SimEvent e;
    e.kind = SimEvent::Kind::Raw;
    e.t = t;
    e.sensor = i;
    e.actor = actor < scene.actors.size() ? scene.actors[actor].person_id : 0;
    s->stamp_ns = sensor_stamp_ns(st.config, t, cfg_.epoch_ns);
    s->frame_number = st.frame;
    e.skeleton = std::move(*s);
    out.push_back(std::move(e));
  }
  if (cfg_.emit_frames) {
    SimEvent f;
    f.kind = SimEvent::Kind::Frame;
    f.t = t;
    f.sensor = i;
    f.people = people;
    f.skeleton.sensor_id = st.config.id;
    f.skeleton.stamp_ns = sensor_stamp_ns(st.config, t, cfg_.epoch_ns);
    f.skeleton.frame_number = st.frame;
    out.push_back(std::move(f));
  }
}

std::vector<SimEvent> Simulation::advance(double t) {
  std::vector<SimEvent> out;
  for (;;) {
    // The earliest pending event; truth first on a tie.
    double best = t;
    int which = -2;  // -1 truth, >= 0 a sensor
    const double next_truth = static_cast<double>(truth_frame_) / cfg_.truth_rate_hz;
    if (next_truth < scenario_.duration() && next_truth < best) {
      best = next_truth;
      which = -1;
    }
    for (std::size_t i = 0; i < sensors_.size(); ++i) {
      const auto& s = *sensors_[i];
      if (s.next < s.times.size() && s.times[s.next] < best) {
        best = s.times[s.next];
        which = static_cast<int>(i);
      }
    }
    if (which == -2) break;
    if (which == -1) {
      emit_truth(best, out);
      ++truth_frame_;
    } else {
      emit_raw(static_cast<std::size_t>(which), best, out);
      ++sensors_[static_cast<std::size_t>(which)]->next;
    }
  }
  return out;
}

}  // namespace skelgraph::sim
