#include "skelgraph/eval/offline.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace skelgraph::eval {

namespace {
// A skeleton's body frame: x to its left (shoulders), y up, z forward;
// empty without both shoulders.
std::optional<Eigen::Matrix3d> body_frame(const skeleton::Skeleton& s) {
  const auto& l = s[skeleton::JointId::LeftShoulder];
  const auto& r = s[skeleton::JointId::RightShoulder];
  if (l.confidence <= 0 || r.confidence <= 0) return std::nullopt;
  Eigen::Vector3d x = l.position - r.position;
  x.y() = 0;
  if (x.norm() < 1e-6) return std::nullopt;
  x.normalize();
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  Eigen::Matrix3d m;
  m.col(0) = x;
  m.col(1) = y;
  m.col(2) = x.cross(y);
  return m;
}

// Constant per-joint offsets of a stream against the truth, in the truth's
// body frame (where a tracker's convention offsets are constant). Learnt
// robustly on the calibration segment: only while the person stands still
// (a moving person adds the tracker's lag), not in the first second after the
// stream picks the person up (a fresh skeleton is still settling), and as the
// per-axis median (a flipped or occluded frame does not drag it).
struct OffsetModel {
  static constexpr std::int64_t kSettleNs = 1'000'000'000;
  static constexpr double kStillMps = 0.25;
  std::array<std::vector<Eigen::Vector3d>, skeleton::kJointCount> samples;
  std::array<Eigen::Vector3d, skeleton::kJointCount> offset{};
  std::array<bool, skeleton::kJointCount> known{};
  std::int64_t reporting_since = -1, last_seen = -1;
  bool solved = false;

  // Called on every scored tick of the segment; `speed` is the truth torso's.
  void learn(const skeleton::Skeleton& est, const skeleton::Skeleton& truth, std::int64_t t, double speed) {
    if (last_seen < 0 || t - last_seen > 200'000'000) reporting_since = t;
    last_seen = t;
    if (t - reporting_since < kSettleNs || speed > kStillMps) return;
    const auto R = body_frame(truth);
    if (!R) return;
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      if (est.joints[j].confidence < skeleton::kTracked) continue;
      samples[j].push_back(R->transpose() * (est.joints[j].position - truth.joints[j].position));
    }
  }
  void solve() {
    if (solved) return;
    solved = true;
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      auto& v = samples[j];
      if (v.size() < 10) continue;  // too little to say: left as it is
      for (int a = 0; a < 3; ++a) {
        std::vector<double> c;
        for (const auto& x : v) c.push_back(x[a]);
        std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
        offset[j][a] = c[c.size() / 2];
      }
      known[j] = true;
      v.clear();
      v.shrink_to_fit();
    }
  }
  skeleton::Skeleton apply(skeleton::Skeleton est, const skeleton::Skeleton& truth) {
    solve();
    const auto R = body_frame(truth);
    if (!R) return est;
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      if (known[j]) est.joints[j].position -= *R * offset[j];
    }
    return est;
  }
};
}  // namespace

struct Evaluator::Impl {
  struct Lane {
    enum class Kind { Single, Method, Recorded };
    Kind kind = Kind::Method;
    StreamScore score;
    fusion::Fuser fuser;
    std::string only_sensor;  // singles: the one sensor fed
    fusion::Method method = fusion::Method::Avg;
    OffsetModel offsets;
    std::string recorded;  // a live fusion component's output id: its recorded skeletons, no fuser
    std::map<std::uint32_t, std::pair<std::int64_t, skeleton::Skeleton>> latest;  // recorded: per person
    std::map<std::uint32_t, std::uint32_t> id_of_truth;  // true person -> the output id it last had
    std::map<std::uint32_t, std::int64_t> matched_at;    // true person -> when it last had an output
  };

  std::map<std::string, Eigen::Isometry3d> poses;
  OfflineOptions options;
  FusedSink sink;
  std::int64_t horizon_ns;
  std::vector<Lane> lanes;
  std::deque<TimedSkeleton> pending;  // added, not yet consumed by a tick
  TruthTimeline truth;
  OfflineResult result;
  std::int64_t first_truth = 0, last_event = 0, last_raw = 0, next_tick = 0;
  std::int64_t last_scored_tick = std::numeric_limits<std::int64_t>::min();
  double tick_s = 0;  // since the tick before (at most 0.1 s), for person_seconds
  std::int64_t done_until = std::numeric_limits<std::int64_t>::min();
  bool any_truth = false, any_raw = false, any_event = false;
  std::size_t next_tick_index = 0;  // into options.tick_times

  Impl(std::map<std::string, Eigen::Isometry3d> p, OfflineOptions o, FusedSink s, std::int64_t h)
      : poses(std::move(p)), options(std::move(o)), sink(std::move(s)), horizon_ns(h) {}

  void make_lane(Lane::Kind kind, const std::string& name, fusion::Method m, const std::string& only,
                 const std::string& recorded) {
    auto fo = options.fuser;
    fo.method = m;
    Lane lane{kind, {}, fusion::Fuser(fo), only, m, {}, recorded, {}, {}, {}};
    lane.score.name = name;
    lane.score.fused = kind != Lane::Kind::Single;
    lane.score.ticks = result.ticks;  // a stream added late had nothing to show on the ticks before
    for (const auto& [id, pose] : poses) lane.fuser.set_pose(id, pose);
    lanes.push_back(std::move(lane));
  }
  void ensure_lane(const TimedSkeleton& e) {
    if (e.kind == TimedSkeleton::Kind::Raw && options.singles) {
      for (const auto& l : lanes)
        if (l.kind == Lane::Kind::Single && l.only_sensor == e.skeleton.sensor_id) return;
      make_lane(Lane::Kind::Single, e.skeleton.sensor_id, fusion::Method::Avg, e.skeleton.sensor_id, "");
    } else if (e.kind == TimedSkeleton::Kind::Fused) {
      for (const auto& l : lanes)
        if (l.recorded == e.skeleton.sensor_id) return;
      make_lane(Lane::Kind::Recorded, "live " + e.skeleton.sensor_id, fusion::Method::Avg, "", e.skeleton.sensor_id);
    }
  }

  // The next tick, if there is one before `limit` (inclusive).
  std::optional<std::int64_t> tick_before(std::int64_t limit) const {
    if (!options.tick_times.empty()) {
      if (next_tick_index < options.tick_times.size() && options.tick_times[next_tick_index] <= limit)
        return options.tick_times[next_tick_index];
      return std::nullopt;
    }
    if (!any_raw || next_tick > limit) return std::nullopt;
    return next_tick;
  }
  void advance_tick() {
    if (!options.tick_times.empty()) ++next_tick_index;
    else next_tick += options.period_ns;
  }

  void run_ticks(std::int64_t limit) {
    while (const auto tick = tick_before(limit)) {
      run_tick(*tick);
      done_until = *tick;
      advance_tick();
    }
  }

  void run_tick(std::int64_t tick) {
    // Everything that arrived up to this tick goes in first.
    for (; !pending.empty() && pending.front().t_ns <= tick; pending.pop_front()) {
      const auto& e = pending.front();
      if (e.kind == TimedSkeleton::Kind::Fused) {
        for (auto& lane : lanes) {
          if (lane.recorded == e.skeleton.sensor_id) lane.latest[e.skeleton.person_id] = {e.t_ns, e.skeleton};
        }
      }
      if (e.kind != TimedSkeleton::Kind::Raw) continue;
      for (auto& lane : lanes) {
        if (!lane.recorded.empty()) continue;
        if (lane.only_sensor.empty() || lane.only_sensor == e.skeleton.sensor_id) lane.fuser.add(e.skeleton, e.t_ns);
      }
    }
    ++result.ticks;
    const std::int64_t at = tick - options.fuser.delay_ns;
    truth.forget_before(at - 1'000'000'000);
    const bool truth_here = truth.covers(at);
    tick_s = last_scored_tick == std::numeric_limits<std::int64_t>::min()
                 ? 0.0
                 : std::min(0.1, static_cast<double>(tick - last_scored_tick) * 1e-9);
    last_scored_tick = tick;
    const bool truth_at_use = options.use_delay_ns > 0 && truth.covers(at + options.use_delay_ns);
    const auto people = truth_here ? truth.all_at(at) : std::vector<skeleton::Skeleton>{};
    // Per lane and true person (or, without truth, per lane): its output has
    // the whole upper body at confidence 1.
    std::vector<std::vector<bool>> complete(lanes.size(), std::vector<bool>(std::max<std::size_t>(people.size(), 1), false));
    for (std::size_t i = 0; i < lanes.size(); ++i) {
      auto& lane = lanes[i];
      std::vector<skeleton::Skeleton> fused;
      if (lane.recorded.empty()) {
        fused = lane.fuser.fuse(tick);
      } else {
        // What the live component last published for each person, if recent.
        for (auto it = lane.latest.begin(); it != lane.latest.end();) {
          if (tick - it->second.first > options.fuser.max_age_ns) {
            it = lane.latest.erase(it);
          } else {
            fused.push_back(it->second.second);
            ++it;
          }
        }
      }
      ++lane.score.ticks;
      if (sink && lane.only_sensor.empty() && lane.recorded.empty()) {
        for (const auto& f : fused) sink(lane.method, f);
      }
      if (!fused.empty()) ++lane.score.with_output;
      for (const auto& f : fused) {
        lane.score.steadiness.add(f);
        if (!truth_here) complete[i][0] = complete[i][0] || upper_body_complete(f);
      }
      if (truth_at_use) score_at_use(lane, fused, at + options.use_delay_ns);
      if (!truth_here) continue;
      const auto pairs = match(fused, people, lane.id_of_truth);
      for (const auto& pr : pairs) complete[i][pr.person] = upper_body_complete(fused[pr.output]);
      score(lane, fused, people, pairs, at);
    }
    for (std::size_t p = 0; p < complete.front().size() && !lanes.empty(); ++p) {
      bool any_single = false;
      for (std::size_t i = 0; i < lanes.size(); ++i) any_single = any_single || (lanes[i].kind == Lane::Kind::Single && complete[i][p]);
      if (!any_single) continue;
      for (std::size_t i = 0; i < lanes.size(); ++i) {
        ++lanes[i].score.ticks_single_complete;
        if (complete[i][p]) ++lanes[i].score.complete_when_single;
      }
    }
  }

  // Which output is which true person, one to one, within 1 m (torso to the
  // output's centre): as in the CLEAR MOT metrics, a person keeps the output
  // id it had if that output is still within 1 m; the rest pair up closest
  // first. An output left over is a ghost, a person left over is missed. In
  // order of distance.
  struct Pair {
    std::size_t output, person;
    double distance;
  };
  static std::vector<Pair> match(const std::vector<skeleton::Skeleton>& fused, const std::vector<skeleton::Skeleton>& people,
                                 const std::map<std::uint32_t, std::uint32_t>& previous) {
    std::vector<Pair> all;
    for (std::size_t o = 0; o < fused.size(); ++o) {
      const auto c = skeleton::centre_of(fused[o]);
      if (!c) continue;
      for (std::size_t p = 0; p < people.size(); ++p) {
        const double d = (people[p][skeleton::JointId::Torso].position - *c).norm();
        if (d <= 1.0) all.push_back({o, p, d});
      }
    }
    std::stable_sort(all.begin(), all.end(), [](const Pair& a, const Pair& b) { return a.distance < b.distance; });
    std::vector<Pair> out;
    std::vector<bool> output_used(fused.size(), false), person_used(people.size(), false);
    for (const bool kept : {true, false}) {
      for (const auto& pr : all) {
        if (output_used[pr.output] || person_used[pr.person]) continue;
        const auto was = previous.find(people[pr.person].person_id);
        if (kept && (was == previous.end() || was->second != fused[pr.output].person_id)) continue;
        output_used[pr.output] = person_used[pr.person] = true;
        out.push_back(pr);
      }
    }
    std::stable_sort(out.begin(), out.end(), [](const Pair& a, const Pair& b) { return a.distance < b.distance; });
    return out;
  }

  // Each true person is scored against the output matched to it (match());
  // a person without one is a missed frame.
  // At the time of use: each output against where its person is then (the truth nearest it).
  void score_at_use(Lane& lane, const std::vector<skeleton::Skeleton>& fused, std::int64_t at) {
    for (const auto& f : fused) {
      const auto c = skeleton::centre_of(f);
      const auto t = c ? truth.at(at, *c) : std::nullopt;
      if (!t || ((*t)[skeleton::JointId::Torso].position - *c).norm() > 1.0) continue;  // a ghost
      lane.score.at_use.add(f, *t);
    }
  }

  void score(Lane& lane, const std::vector<skeleton::Skeleton>& fused, const std::vector<skeleton::Skeleton>& people,
             const std::vector<Pair>& pairs, std::int64_t at) {
    TracePoint tp;
    tp.t_ns = at;
    tp.error_cm.fill(std::nan(""));
    bool traced = false;  // the trace follows the closest pair
    for (const auto& pr : pairs) {
      const auto& f = fused[pr.output];
      const auto* t = &people[pr.person];
      const auto [was, first] = lane.id_of_truth.try_emplace(t->person_id, f.person_id);
      if (!first && was->second != f.person_id) {
        ++lane.score.id_switches;
        if (at - lane.matched_at[t->person_id] > 1'000'000'000) ++lane.score.id_switches_after_gap;
        was->second = f.person_id;
      }
      lane.matched_at[t->person_id] = at;
      lane.score.person_seconds += tick_s;
      lane.score.accuracy.add(f, *t);
      lane.score.uncertainty.add(f, *t);
      if (at - first_truth < static_cast<std::int64_t>(options.compensation_s * 1e9)) {
        const auto before = truth.at(at - 100'000'000, (*t)[skeleton::JointId::Torso].position);
        const double speed =
            before ? ((*t)[skeleton::JointId::Torso].position - (*before)[skeleton::JointId::Torso].position).norm() / 0.1
                   : std::numeric_limits<double>::infinity();
        lane.offsets.learn(f, *t, at, speed);
      } else {
        lane.score.compensated.add(lane.offsets.apply(f, *t), *t);
        lane.score.after_calibration.add(f, *t);
      }
      if (options.trace && !traced) {
        traced = true;
        std::array<double, kGroupCount> sum{}, n{};
        for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
          const int g = group_of(skeleton::joint_at(j));
          if (g < 0 || f.joints[j].confidence < skeleton::kTracked) continue;
          sum[g] += 100.0 * (f.joints[j].position - t->joints[j].position).norm();
          n[g] += 1;
        }
        for (std::size_t g = 0; g < kGroupCount; ++g) tp.error_cm[g] = n[g] > 0 ? sum[g] / n[g] : std::nan("");
        const auto& tj = f[options.trace_joint];
        if (tj.confidence >= skeleton::kTracked) tp.joint = tj.position;
        tp.truth = (*t)[options.trace_joint].position;
      }
    }
    for (std::size_t missed = pairs.size(); missed < people.size(); ++missed) {
      lane.score.accuracy.add_missed();
      if (at - first_truth >= static_cast<std::int64_t>(options.compensation_s * 1e9)) {
        lane.score.compensated.add_missed();
        lane.score.after_calibration.add_missed();
      }
    }
    if (options.trace) lane.score.trace.push_back(tp);
  }

  void add(TimedSkeleton e) {
    if (any_event && e.t_ns < last_event)
      throw std::invalid_argument("evaluation: events out of time order (" + std::to_string(e.t_ns) + " ns after " +
                                  std::to_string(last_event) + " ns)");
    any_event = true;
    last_event = e.t_ns;
    ensure_lane(e);
    if (e.kind == TimedSkeleton::Kind::Truth) {
      truth.add(e.skeleton, e.t_ns);
      if (!any_truth) first_truth = e.t_ns;
      any_truth = true;
      result.has_truth = true;
    } else if (e.kind == TimedSkeleton::Kind::Raw) {
      if (!any_raw) next_tick = e.t_ns;
      any_raw = true;
      last_raw = e.t_ns;
    }
    pending.push_back(std::move(e));
    run_ticks(last_event - horizon_ns);
  }

  OfflineResult finish() {
    if (any_raw) run_ticks(options.tick_times.empty() ? last_raw + options.period_ns : std::numeric_limits<std::int64_t>::max());
    pending.clear();
    // Singles first (sensor order), then methods, then recorded live fusion.
    std::stable_sort(lanes.begin(), lanes.end(), [](const Lane& a, const Lane& b) { return a.kind < b.kind; });
    OfflineResult r = std::move(result);
    if (!any_raw) r.ticks = 0;
    for (auto& lane : lanes) {
      if (!any_raw) break;  // nothing to fuse: no streams
      r.streams.push_back(std::move(lane.score));
      r.fuser_stats.push_back(lane.fuser.stats());
    }
    lanes.clear();
    return r;
  }
};

Evaluator::Evaluator(std::map<std::string, Eigen::Isometry3d> world_from_sensor, const std::vector<std::string>& sensor_ids,
                     const std::vector<std::string>& recorded_ids, OfflineOptions options, FusedSink sink,
                     std::int64_t horizon_ns)
    : impl_(std::make_unique<Impl>(std::move(world_from_sensor), std::move(options), std::move(sink), horizon_ns)) {
  using Kind = Impl::Lane::Kind;
  if (impl_->options.singles) {
    for (const auto& id : sensor_ids) impl_->make_lane(Kind::Single, id, fusion::Method::Avg, id, "");
  }
  for (const auto m : impl_->options.methods) impl_->make_lane(Kind::Method, fusion::method_name(m), m, "", "");
  for (const auto& id : recorded_ids) impl_->make_lane(Kind::Recorded, "live " + id, fusion::Method::Avg, "", id);
}

Evaluator::~Evaluator() = default;
void Evaluator::add(TimedSkeleton event) { impl_->add(std::move(event)); }
std::size_t Evaluator::pending() const { return impl_->pending.size(); }
std::int64_t Evaluator::done_until() const { return impl_->done_until; }
OfflineResult Evaluator::finish() { return impl_->finish(); }

OfflineResult evaluate(const std::map<std::string, Eigen::Isometry3d>& world_from_sensor,
                       const std::vector<TimedSkeleton>& events, const OfflineOptions& options,
                       const FusedSink& sink) {
  std::vector<std::string> sensor_ids, recorded_ids;
  for (const auto& e : events) {
    auto& ids = e.kind == TimedSkeleton::Kind::Raw ? sensor_ids : recorded_ids;
    if (e.kind != TimedSkeleton::Kind::Truth && std::find(ids.begin(), ids.end(), e.skeleton.sensor_id) == ids.end()) {
      ids.push_back(e.skeleton.sensor_id);
    }
  }
  Evaluator ev(world_from_sensor, sensor_ids, recorded_ids, options, sink);
  for (const auto& e : events) ev.add(e);
  return ev.finish();
}

}  // namespace skelgraph::eval
