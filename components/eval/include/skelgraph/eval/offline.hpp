#pragma once
// Offline evaluation of fusion: raw skeletons and ground truth in time order
// go through one Fuser per method (and one per single sensor, so single
// sensors are measured on the same output ticks), and every stream is scored
// against the truth at its tick. DDS-free and single-threaded; `skelgraph
// eval` feeds it from the simulator or from a recording.

#include <cstdint>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/eval/metrics.hpp"
#include "skelgraph/fusion/fuser.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::eval {

struct TimedSkeleton {
  // Fused: what a live fusion component published (scored as the stream
  // "live <sensor_id>", beside the offline re-runs of every method).
  enum class Kind { Raw, Truth, Fused };
  Kind kind = Kind::Raw;
  std::int64_t t_ns = 0;       // arrival (raw, fused) or truth time, on one clock
  skeleton::Skeleton skeleton;  // raw: its sensor's frame; truth and fused: world
};

struct OfflineOptions {
  std::vector<fusion::Method> methods = {fusion::Method::Avg, fusion::Method::Sum, fusion::Method::Facing,
                                         fusion::Method::Weighted, fusion::Method::Kalman};
  fusion::FuserOptions fuser;        // method is set per stream
  std::int64_t period_ns = 33'333'333;  // output ticks (30 Hz)...
  std::vector<std::int64_t> tick_times;  // ...unless given (sync TICKs in a recording), in order
  bool singles = true;                // also every sensor on its own
  bool trace = false;                 // keep per-tick series for plots (StreamScore::trace)
  // Constant per-joint offsets between the stream's skeleton convention and
  // the truth's, estimated in the stream's own body frame over the first
  // `compensation_s` of truth and removed afterwards (StreamScore::compensated).
  double compensation_s = 5.0;
  skeleton::JointId trace_joint = skeleton::JointId::RightHand;
  // Every stream also scored against the truth this long after each
  // output's time (StreamScore::at_use): where the person is when a consumer
  // uses it. 0: not scored so. At most 1 s (the evaluation holds 2 s of
  // truth ahead).
  std::int64_t use_delay_ns = 0;
};

// One output tick of one stream, for plots.
struct TracePoint {
  std::int64_t t_ns = 0;
  std::array<double, kGroupCount> error_cm{};  // per group, mean over its joints at confidence 1; NaN if none
  Eigen::Vector3d joint = Eigen::Vector3d::Constant(std::nan(""));  // the traced joint (NaN if not at confidence 1)
  Eigen::Vector3d truth = Eigen::Vector3d::Constant(std::nan(""));  // the truth of that joint at the tick
};

struct StreamScore {
  std::string name;      // a sensor id, or a method name
  bool fused = false;
  Accumulator accuracy;  // against truth at the output's own time (empty without truth)
  Accumulator at_use;    // against truth OfflineOptions::use_delay_ns later (empty when 0)
  Accumulator after_calibration;  // the same ticks as `compensated`, offsets kept (the fair comparison)
  Accumulator compensated;        // after the calibration segment, with per-joint offsets removed
  Steadiness steadiness;
  UncertaintyCheck uncertainty;   // against truth, the joints that carry a covariance (kalman)
  std::uint64_t ticks = 0, with_output = 0;
  // Outputs are matched to true people one to one, closest pairs first
  // (torso within 1 m); every true person in the truth counts on every tick
  // (a person without a matched output is a missed frame in `accuracy`).
  // Identity: times a true person's matched output carried another person
  // id than the last output that person had; and the seconds true people
  // had an output, summed over people.
  std::uint64_t id_switches = 0;
  // ... of them, switches after the person had had no output for over a
  // second (hidden from every sensor, or outside their view: without
  // appearance, nobody can tell it is the same person)
  std::uint64_t id_switches_after_gap = 0;
  double person_seconds = 0;
  double id_switches_per_person_minute() const {
    return person_seconds > 0 ? 60.0 * static_cast<double>(id_switches) / person_seconds : std::nan("");
  }
  // Person-ticks (with truth: each true person on each tick, its matched
  // output; without: each tick, any output) on which some single sensor had
  // the whole upper body at confidence 1, and of those, the ones this stream
  // had it too: how much of what any one sensor tracks the stream keeps.
  std::uint64_t ticks_single_complete = 0, complete_when_single = 0;
  double complete_when_single_pct() const {
    return ticks_single_complete > 0 ? 100.0 * static_cast<double>(complete_when_single) / static_cast<double>(ticks_single_complete) : 0.0;
  }
  std::vector<TracePoint> trace;  // with OfflineOptions::trace
};

struct OfflineResult {
  std::vector<StreamScore> streams;  // singles first (sensor order), then methods, then recorded live fusion
  std::uint64_t ticks = 0;
  bool has_truth = false;
  std::vector<fusion::FuserStats> fuser_stats;  // per stream
};

// Called with every fused skeleton of every method (e.g. to write them to a recording).
using FusedSink = std::function<void(fusion::Method, const skeleton::Skeleton&)>;

// The evaluation one event at a time, for sessions too long to hold in
// memory: events go in in time order and each output tick is fused and scored
// once the events have run `horizon_ns` past it (the truth around a tick is
// then known). Memory stays bounded: the events and truth of the last few
// seconds, plus per-tick traces when asked for. The result is the same as
// evaluate()'s on the whole list, except on ticks within 0.1 s after a
// person's truth stops for longer than the horizon and later resumes.
class Evaluator {
 public:
  // `sensor_ids`: the sensors scored alone, in output order; `recorded_ids`:
  // the recorded live fusion streams. An id first seen later gets its
  // stream then, scored from that tick on.
  Evaluator(std::map<std::string, Eigen::Isometry3d> world_from_sensor, const std::vector<std::string>& sensor_ids,
            const std::vector<std::string>& recorded_ids, OfflineOptions options, FusedSink sink = {},
            std::int64_t horizon_ns = 2'000'000'000);
  ~Evaluator();
  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;

  // Throws std::invalid_argument for an event older than the one before it.
  void add(TimedSkeleton event);
  std::size_t pending() const;  // events held, waiting for their tick
  // The last tick fused and scored so far (every FusedSink call up to it has
  // been made); the lowest int64 before the first.
  std::int64_t done_until() const;
  // Fuses and scores the remaining ticks (to the last raw event + one period, or the last tick_time).
  OfflineResult finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// `events` in time order. Ticks run from the first raw event to the last at
// `period_ns` (or are `tick_times`); a tick counts for accuracy when truth covers it.
OfflineResult evaluate(const std::map<std::string, Eigen::Isometry3d>& world_from_sensor,
                       const std::vector<TimedSkeleton>& events, const OfflineOptions& options,
                       const FusedSink& sink = {});

}  // namespace skelgraph::eval
