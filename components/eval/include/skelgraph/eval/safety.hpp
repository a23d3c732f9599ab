#pragma once
// Speed-and-separation monitoring judged against the truth, offline and
// closed-loop: the simulator's sensors feed the fuser, the `separation`
// core decides on the fused people (its reaction time measured from their
// capture stamps, as live), the simulated arm obeys after a command latency,
// and at every decision the simulator's true people are compared with where
// the arm really is. DDS-free and deterministic (time is the simulation's);
// `skelgraph eval safety` runs it.
//
// Judged at every decision (ISO/TS 15066 S_p with the truth: the true
// separation, the arm's true tool speed, the reaction time the system had
// then, no position uncertainty):
//  - missed: the true separation is below the true S_p while the state is
//    RUN or REDUCED (the robot was allowed to move, too fast for the truth);
//  - an intrusion starts where the true separation drops below the true S_p;
//    a time to stop is counted from there (or from a release while still too
//    close) to the next PROTECTIVE_STOP decision, or to the intrusion's end
//    if none came; 0 when the robot was stopped already;
//  - unnecessary: PROTECTIVE_STOP while the truth leaves room for a useful
//    speed (the true separation at least S_p at min_scale times the asked
//    speed, plus 0.3 m).

#include <array>
#include <cmath>
#include <optional>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/fusion/fuser.hpp"
#include "skelgraph/robot/follow.hpp"
#include "skelgraph/robot/separation.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::eval {

struct SafetyRunOptions {
  sim::SimConfig sim;               // scenario, seed, sensors; frames are always emitted
  fusion::FuserOptions fuser;       // the fusion method etc.
  std::int64_t capture_latency_ns = 50'000'000;  // the trackers' delay (NITE)
  double fuse_period_s = 1.0 / 30.0;
  double hop_s = 0.001;             // sensor to fusion
  // The arm: where it stands and its task (the tool round these points).
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> task;
  double task_speed = 0.5;          // m/s, also the speed asked of it (robot_max_speed)
  robot::SeparationParams params;
  double release_s = 0.5;
  double uncertainty_scale = 1.0;   // Z_d: the fused joints' 95 % radius times this (0: left out, to see what it costs)
  // A perfect tracker: the monitor sees the true people as they were the
  // trackers' capture latency (plus the hop) ago, at the fusion rate, with no
  // uncertainty. What is left is the floor the formula, the latencies and the
  // release hold set, whatever the sensors.
  bool perfect_tracker = false;
  bool arm_hides = true;            // the arm's links hide people from the sensors behind it (as a real arm does)
  double decision_rate_hz = 100.0;  // decisions and arm steps per second
  double command_latency_s = 0.01;  // from a decision to the arm acting on it (and in the reaction time)
  double unnecessary_margin_m = 0.3;
  // Instead of its task, the arm follows a worker's hand (robot/follow.hpp).
  std::optional<robot::FollowParams> follow;
  double trace_period_s = 0;        // > 0: a TracePoint this often (for plots)
  // A sensor falling silent (no frames, no skeletons) for `for_s` every
  // `every_s` seconds, from `from_s` on: the monitor sees it as lost after
  // sensor_timeout_s; fewer live sensors than min_sensors is a stop.
  struct Dropout {
    std::string sensor;
    double from_s = 0, every_s = 0, for_s = 0;
    bool silent(double t) const {
      if (t < from_s) return false;
      return every_s > 0 ? std::fmod(t - from_s, every_s) < for_s : t - from_s < for_s;
    }
  };
  std::vector<Dropout> dropouts;
  double sensor_timeout_s = 0.5;
  int min_sensors = 2;
};

// The run over time, for plots: separations (m; NaN: nobody) and the state.
struct SafetyTracePoint {
  double t = 0;
  double true_m = 0, seen_m = 0;  // the truth's and the fused people's separation from the arm
  double protective_m = 0;        // S_p the monitor used (its speed, reaction time, Z_d)
  robot::SafetyState state = robot::SafetyState::ProtectiveStop;
};

struct SafetyRunResult {
  double seconds = 0;
  std::uint64_t steps = 0;
  std::map<std::string, std::uint64_t> steps_by_state;  // RUN, REDUCED, PROTECTIVE_STOP
  std::uint64_t missed_steps = 0;       // see above; the target is 0
  std::uint64_t unnecessary_steps = 0;
  std::uint64_t stop_steps = 0;
  std::uint64_t intrusions = 0;         // ... of a robot allowed to move
  std::vector<double> time_to_stop_ms;  // one per intrusion
  std::vector<double> reaction_ms;      // the reaction time of every decision with people
  double min_true_separation_m = 0;     // over the run (+inf: nobody)
  std::uint64_t task_points_reached = 0;
  std::uint64_t stops = 0;              // protective stops commanded
  // follow: steps with a hand to follow, and of those the ones the arm was
  // allowed to move; the tool's distance then from where the true hand
  // would put it (the same standoff and workspace), m.
  std::uint64_t follow_steps = 0, follow_moving_steps = 0;
  std::vector<double> follow_error_m;
  std::vector<double> follow_hand_speed;  // the true hand's speed at each of those steps, m/s
  // Moving steps with the tool outside the workspace box (by more than 1 mm)
  // once it has been inside it; the target is 0.
  std::uint64_t follow_outside_steps = 0;
  // The lag: for a delay of i decision steps (i = 0 .. kFollowLagSteps), the
  // tool's summed distance from where the true hand would have put it i steps
  // before, over the moving steps that have both.
  static constexpr int kFollowLagSteps = 100;
  std::vector<double> follow_lag_sum_m;
  std::vector<std::uint64_t> follow_lag_n;
  double decision_period_s = 0;  // one decision step, s
  std::vector<SafetyTracePoint> trace;  // with trace_period_s

  // n steps as a share of all steps, % (0 without steps).
  double share_pct(std::uint64_t n) const {
    return steps > 0 ? 100.0 * static_cast<double>(n) / static_cast<double>(steps) : 0.0;
  }

  // The tool's distance from the true hand's target at or below a hand speed
  // (m/s), in the order of follow_error_m.
  std::vector<double> follow_error_at_most(double hand_speed) const;
  // The delay at which the tool is nearest where the true hand would have put
  // it (least mean distance), ms; 0 without moving steps.
  double follow_lag_ms() const;
};

// Several runs as one: counts and times added, the per-event lists joined (in
// run order), the smallest separation kept (+inf for no runs); no trace.
SafetyRunResult combine(const std::vector<SafetyRunResult>& runs);

// "SENSOR,EVERY_S,FOR_S": the sensor silent FOR_S seconds in every EVERY_S
// (from EVERY_S - FOR_S on). Throws std::invalid_argument, quoting the spec,
// for a malformed one, a sensor not among `sensors`, or not 0 < FOR_S < EVERY_S.
SafetyRunOptions::Dropout parse_dropout(const std::string& spec, const std::vector<std::string>& sensors);

// bringup/robot_cell.yaml's cell: the `robot` scenario watched by four
// sensors in a ring, the arm's base 1.9 m ahead of the worker, its tool round
// four points beside the walkway at 0.5 m/s.
SafetyRunOptions robot_cell_options();

// One run of the scenario (sim.scenario, its repeats) from start to end.
// Throws std::invalid_argument for a bad configuration (an empty task).
SafetyRunResult run_safety(const SafetyRunOptions& options);

// The quantile q of values (nearest rank); 0 when empty.
double quantile(std::vector<double> values, double q);

}  // namespace skelgraph::eval
