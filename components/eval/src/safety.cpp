#include "skelgraph/eval/safety.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "skelgraph/robot/arm.hpp"
#include "skelgraph/robot/capsule.hpp"

namespace skelgraph::eval {

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(std::ceil(q * static_cast<double>(values.size())) - 1.0, 0.0,
                                                     static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

std::vector<double> SafetyRunResult::follow_error_at_most(double hand_speed) const {
  std::vector<double> out;
  for (std::size_t i = 0; i < follow_error_m.size() && i < follow_hand_speed.size(); ++i) {
    if (follow_hand_speed[i] <= hand_speed) out.push_back(follow_error_m[i]);
  }
  return out;
}

double SafetyRunResult::follow_lag_ms() const {
  std::size_t best = 0;
  double best_mean = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < follow_lag_sum_m.size() && i < follow_lag_n.size(); ++i) {
    if (follow_lag_n[i] == 0) continue;
    const double mean = follow_lag_sum_m[i] / static_cast<double>(follow_lag_n[i]);
    if (mean < best_mean) {
      best_mean = mean;
      best = i;
    }
  }
  return static_cast<double>(best) * decision_period_s * 1e3;
}

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// The closest of `people` to the arm: surface distance, and which capsule (for its uncertainty).
struct Nearest {
  double distance = kInf;
  double uncertainty = 0;
};
Nearest nearest(const std::vector<skeleton::Skeleton>& people, const std::vector<robot::Capsule>& arm) {
  Nearest n;
  for (const auto& p : people) {
    const auto c = robot::separation_to(p, arm);
    if (c.distance < n.distance) {
      n.distance = c.distance;
      n.uncertainty = c.uncertainty_m;
    }
  }
  return n;
}
}  // namespace

SafetyRunOptions robot_cell_options() {
  SafetyRunOptions o;
  o.sim.scenario.name = "robot";
  o.sim.sensors = sim::layout_sensors("ring", 4);
  o.world_from_base = robot::base_pose(0.0, 0.0, 1.9, 180.0);
  o.task = {{0.45, 0.6, 1.5}, {-0.45, 0.6, 1.5}, {-0.3, 0.3, 1.35}, {0.3, 0.3, 1.35}};
  o.task_speed = 0.5;
  return o;
}

SafetyRunResult run_safety(const SafetyRunOptions& o) {
  if (o.task.empty() && !o.follow) throw std::invalid_argument("safety run: the arm needs a task (points for its tool) or a hand to follow");
  if (!(o.decision_rate_hz > 0) || !(o.fuse_period_s > 0))
    throw std::invalid_argument("safety run: decision rate and fusion period must be positive");
  auto cfg = o.sim;
  cfg.emit_frames = true;
  cfg.emit_departures = true;
  sim::Simulation sim(cfg);
  fusion::Fuser fuser(o.fuser);
  for (const auto& s : cfg.sensors) {
    fuser.set_pose(s.id, s.world_from_sensor());
    fuser.set_capture_latency(s.id, o.capture_latency_ns);
  }
  robot::Joints start;
  start << 0.0, -M_PI / 2, M_PI / 2, -M_PI / 2, -M_PI / 2, 0.0;
  robot::ArmSim arm(robot::ArmModel::ur5e(), o.world_from_base, start);
  const auto& stopping = arm.model().stopping;
  robot::StopLatch latch(o.release_s);

  SafetyRunResult r;
  r.min_true_separation_m = kInf;
  const double dt = 1.0 / o.decision_rate_hz;
  const auto steps = static_cast<std::uint64_t>(std::floor(sim.duration() / dt));
  std::vector<skeleton::Skeleton> people;  // the latest fused output
  std::int64_t last_frame_ns = std::numeric_limits<std::int64_t>::min();
  double next_fuse = 0.0, next_trace = 0.0;
  std::map<std::string, std::int64_t> sensor_seen_ns;  // last frame per sensor
  struct Command {
    double at;
    robot::SafetyState state;
    double scale;
  };
  std::deque<Command> commands;
  bool decided_once = false;
  robot::SafetyDecision last;
  std::size_t task_next = 0;
  std::optional<robot::Follower> follower;
  if (o.follow) follower.emplace(*o.follow, o.world_from_base.translation());
  bool danger_before = false, waiting_for_stop = false;
  double danger_since = 0.0;
  // Following: where the true hand would have put the tool, newest first (none
  // while holding), for the lag; the true people a step before, for the hand's speed.
  std::deque<std::optional<Eigen::Vector3d>> wants;
  std::vector<skeleton::Skeleton> truths_before;
  bool tool_was_inside = false;
  r.decision_period_s = dt;
  r.follow_lag_sum_m.assign(SafetyRunResult::kFollowLagSteps + 1, 0.0);
  r.follow_lag_n.assign(SafetyRunResult::kFollowLagSteps + 1, 0);

  for (std::uint64_t k = 0; k < steps; ++k) {
    const double now = static_cast<double>(k) * dt;
    const std::int64_t now_ns = std::llround(now * 1e9);
    // The arm where it is now hides whoever is behind it from the sensors.
    if (o.arm_hides) {
      std::vector<sim::Capsule> links;
      for (const auto& c : arm.capsules()) links.push_back({c.a, c.b, c.radius});
      sim.set_occluders(std::move(links));
    }
    // What reached fusion by now (a hop after the sensor delivered it).
    for (auto& e : sim.advance(now - o.hop_s)) {
      const std::int64_t arrival = std::llround((e.t + o.hop_s) * 1e9);
      const auto& id = e.skeleton.sensor_id;
      if (std::any_of(o.dropouts.begin(), o.dropouts.end(), [&](const auto& d) { return d.sensor == id && d.silent(e.t); }))
        continue;  // a silent sensor delivers nothing
      switch (e.kind) {
        case sim::SimEvent::Kind::Raw: fuser.add(e.skeleton, arrival); break;
        case sim::SimEvent::Kind::Frame:
          fuser.heartbeat(e.skeleton.sensor_id, arrival);
          last_frame_ns = std::max(last_frame_ns, arrival);
          sensor_seen_ns[e.skeleton.sensor_id] = arrival;
          break;
        case sim::SimEvent::Kind::Lost: fuser.remove(e.skeleton.sensor_id, e.skeleton.person_id); break;
        default: break;
      }
    }
    if (now + 1e-12 >= next_fuse) {
      people = fuser.fuse(now_ns);
      if (o.perfect_tracker) {
        const double captured = now - static_cast<double>(o.capture_latency_ns) * 1e-9 - o.hop_s;
        people = captured >= 0 ? sim.truth_at(captured) : std::vector<skeleton::Skeleton>{};
        for (auto& p : people) p.capture_newest_ns = std::llround(captured * 1e9);
      }
      next_fuse += o.fuse_period_s;
    }

    // The decision, as the separation component makes it.
    const auto arm_caps = arm.capsules();
    robot::SeparationInput in;
    in.robot_age_s = 0.0;
    int live = 0;
    for (const auto& [sensor, seen_ns] : sensor_seen_ns) live += static_cast<double>(now_ns - seen_ns) * 1e-9 <= o.sensor_timeout_s;
    in.coverage_lost = live < o.min_sensors;
    in.robot_speed = arm.tool_speed();
    in.robot_max_speed = o.task_speed;
    double age = last_frame_ns == std::numeric_limits<std::int64_t>::min() ? kInf
                                                                            : static_cast<double>(now_ns - last_frame_ns) * 1e-9;
    if (!people.empty()) age = 0.0;
    for (const auto& p : people) {
      if (!skeleton::centre_of(p)) in.unplaced_person = true;
      const std::int64_t capture = p.capture_newest_ns != 0 ? p.capture_newest_ns : p.stamp_ns;
      age = std::max(age, static_cast<double>(now_ns - capture) * 1e-9);
    }
    const auto seen = nearest(people, arm_caps);
    in.separation_m = seen.distance;
    in.person_uncertainty_m = o.uncertainty_scale * seen.uncertainty;
    in.closest = "person";
    in.people_age_s = age;
    in.reaction_s = age + o.command_latency_s;
    const auto d = latch.apply(robot::decide(o.params, stopping, in), now);
    ++r.steps;
    ++r.steps_by_state[robot::safety_state_name(d.state)];
    if (!people.empty() && std::isfinite(in.reaction_s)) r.reaction_ms.push_back(in.reaction_s * 1e3);
    const bool stop = d.state == robot::SafetyState::ProtectiveStop;
    r.stop_steps += stop ? 1 : 0;

    // Judged against the truth: where the people really are, how fast the arm really moves.
    const auto truth = nearest(sim.truth_at(now), arm_caps);
    if (o.trace_period_s > 0 && now + 1e-9 >= next_trace) {
      const auto finite_or_nan = [](double v) { return std::isfinite(v) ? v : std::nan(""); };
      r.trace.push_back({now, finite_or_nan(truth.distance), finite_or_nan(seen.distance), finite_or_nan(d.protective_m), d.state});
      next_trace += o.trace_period_s;
    }
    r.min_true_separation_m = std::min(r.min_true_separation_m, truth.distance);
    if (std::isfinite(truth.distance) && std::isfinite(in.reaction_s)) {
      const double sp = robot::protective_distance(o.params, stopping, truth.distance, arm.tool_speed(), in.reaction_s, 0.0);
      const bool danger = truth.distance < sp;
      if (danger && !stop) ++r.missed_steps;
      if (danger && !danger_before) {
        ++r.intrusions;
        if (stop) r.time_to_stop_ms.push_back(0.0);  // already stopped
      }
      if (danger && !stop && !waiting_for_stop) {
        // Too close and allowed to move (from the intrusion's start, or from a release within it).
        waiting_for_stop = true;
        danger_since = now;
      }
      if (waiting_for_stop && (stop || !danger)) {
        r.time_to_stop_ms.push_back((now - danger_since) * 1e3);  // (danger over without a stop: as long as it lasted)
        waiting_for_stop = false;
      }
      danger_before = danger;
      const double useful = robot::protective_distance(o.params, stopping, truth.distance,
                                                       o.params.min_scale * o.task_speed, in.reaction_s, 0.0);
      if (stop && truth.distance >= useful + o.unnecessary_margin_m) ++r.unnecessary_steps;
    } else {
      danger_before = false;
      if (stop && !std::isfinite(truth.distance)) ++r.unnecessary_steps;  // nobody there at all
    }

    // Commands on change, as the component sends them, acted on after the latency.
    const bool was_stop = decided_once && last.state == robot::SafetyState::ProtectiveStop;
    if ((stop && (!decided_once || !was_stop)) ||
        (!stop && (!decided_once || was_stop || std::abs(d.speed_scale - last.speed_scale) > 0.02))) {
      commands.push_back({now + o.command_latency_s, d.state, d.speed_scale});
      if (stop && (!decided_once || !was_stop)) ++r.stops;
    }
    decided_once = true;
    last = d;
    while (!commands.empty() && commands.front().at <= now + 1e-12) {
      const auto& c = commands.front();
      if (c.state == robot::SafetyState::ProtectiveStop) {
        arm.protective_stop();
      } else {
        arm.set_speed_scale(c.scale);
        if (arm.stopped()) arm.resume();
      }
      commands.pop_front();
    }
    if (follower) {
      // The hand, as fused: where the tool goes; judged against where the true hand would send it.
      const auto f = follower->step(people, now_ns);
      const auto truths = sim.truth_at(now);
      std::optional<Eigen::Vector3d> want;
      if (f.hold) {
        arm.clear_target();
      } else {
        arm.set_target(f.target, o.task_speed);
        ++r.follow_steps;
        const auto& fused = *std::find_if(people.begin(), people.end(), [&](const auto& p) { return p.person_id == f.person; });
        const Eigen::Vector3d seen_hand = fused[o.follow->joint].position;
        const skeleton::Skeleton* nearest_truth = nullptr;
        for (const auto& t : truths) {
          if (!nearest_truth || (t[o.follow->joint].position - seen_hand).norm() < ((*nearest_truth)[o.follow->joint].position - seen_hand).norm())
            nearest_truth = &t;
        }
        if (nearest_truth) {
          const Eigen::Vector3d hand = (*nearest_truth)[o.follow->joint].position;
          Eigen::Vector3d towards = o.world_from_base.translation() - hand;
          towards.y() = 0;
          if (towards.norm() < 1e-6) towards = Eigen::Vector3d::UnitZ();
          want = (hand + o.follow->standoff_m * towards.normalized())
                     .cwiseMax(o.follow->workspace.min())
                     .cwiseMin(o.follow->workspace.max());
          if (!stop) {
            ++r.follow_moving_steps;
            const Eigen::Vector3d tool = arm.tool_world();
            r.follow_error_m.push_back((tool - *want).norm());
            double speed = kInf;  // unknown (the person new this step): counted as fast
            for (const auto& b : truths_before) {
              if (b.person_id == nearest_truth->person_id) speed = (hand - b[o.follow->joint].position).norm() / dt;
            }
            r.follow_hand_speed.push_back(speed);
            if (o.follow->workspace.exteriorDistance(tool) <= 1e-3) {
              tool_was_inside = true;
            } else if (tool_was_inside) {
              ++r.follow_outside_steps;
            }
          }
        }
      }
      wants.push_front(want);
      if (wants.size() > static_cast<std::size_t>(SafetyRunResult::kFollowLagSteps) + 1) wants.pop_back();
      if (want && !stop) {
        const Eigen::Vector3d tool = arm.tool_world();
        for (std::size_t i = 0; i < wants.size(); ++i) {
          if (!wants[i]) continue;
          r.follow_lag_sum_m[i] += (tool - *wants[i]).norm();
          ++r.follow_lag_n[i];
        }
      }
      truths_before = truths;
    } else {
      // The arm's own task.
      if ((arm.tool_world() - o.task[task_next]).norm() < 0.01) {
        task_next = (task_next + 1) % o.task.size();
        ++r.task_points_reached;
      }
      arm.set_target(o.task[task_next], o.task_speed);
    }
    arm.step(dt);
  }
  r.seconds = static_cast<double>(r.steps) * dt;
  return r;
}

SafetyRunResult combine(const std::vector<SafetyRunResult>& runs) {
  SafetyRunResult all;
  all.min_true_separation_m = std::numeric_limits<double>::infinity();
  const auto join = [](std::vector<double>& to, const std::vector<double>& from) { to.insert(to.end(), from.begin(), from.end()); };
  for (const auto& r : runs) {
    all.seconds += r.seconds;
    all.steps += r.steps;
    for (const auto& [k, v] : r.steps_by_state) all.steps_by_state[k] += v;
    all.missed_steps += r.missed_steps;
    all.intrusions += r.intrusions;
    all.unnecessary_steps += r.unnecessary_steps;
    all.stop_steps += r.stop_steps;
    all.stops += r.stops;
    all.task_points_reached += r.task_points_reached;
    all.follow_steps += r.follow_steps;
    all.follow_moving_steps += r.follow_moving_steps;
    join(all.follow_error_m, r.follow_error_m);
    join(all.follow_hand_speed, r.follow_hand_speed);
    all.follow_outside_steps += r.follow_outside_steps;
    all.decision_period_s = std::max(all.decision_period_s, r.decision_period_s);
    if (all.follow_lag_sum_m.size() < r.follow_lag_sum_m.size()) {
      all.follow_lag_sum_m.resize(r.follow_lag_sum_m.size(), 0.0);
      all.follow_lag_n.resize(r.follow_lag_sum_m.size(), 0);
    }
    for (std::size_t i = 0; i < r.follow_lag_sum_m.size(); ++i) {
      all.follow_lag_sum_m[i] += r.follow_lag_sum_m[i];
      all.follow_lag_n[i] += r.follow_lag_n[i];
    }
    all.min_true_separation_m = std::min(all.min_true_separation_m, r.min_true_separation_m);
    join(all.time_to_stop_ms, r.time_to_stop_ms);
    join(all.reaction_ms, r.reaction_ms);
  }
  return all;
}

SafetyRunOptions::Dropout parse_dropout(const std::string& spec, const std::vector<std::string>& sensors) {
  SafetyRunOptions::Dropout d;
  std::stringstream ss(spec);
  std::string sensor, every, length, extra;
  if (!std::getline(ss, sensor, ',') || !std::getline(ss, every, ',') || !std::getline(ss, length, ',') ||
      std::getline(ss, extra, ',')) {
    throw std::invalid_argument("'" + spec + "': expected SENSOR,EVERY_S,FOR_S (e.g. sensor1,20,5)");
  }
  if (std::find(sensors.begin(), sensors.end(), sensor) == sensors.end()) {
    throw std::invalid_argument("'" + spec + "': no sensor '" + sensor + "' in this cell");
  }
  try {
    d.every_s = std::stod(every);
    d.for_s = std::stod(length);
  } catch (const std::exception&) {
    throw std::invalid_argument("'" + spec + "': EVERY_S and FOR_S must be numbers");
  }
  if (!(d.every_s > 0 && d.for_s > 0 && d.for_s < d.every_s)) throw std::invalid_argument("'" + spec + "': need 0 < FOR_S < EVERY_S");
  d.sensor = sensor;
  d.from_s = d.every_s - d.for_s;
  return d;
}

}  // namespace skelgraph::eval
