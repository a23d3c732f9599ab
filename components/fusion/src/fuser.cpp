#include "skelgraph/fusion/fuser.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <set>
#include <utility>

#include "skelgraph/fusion/joint_filter.hpp"

namespace skelgraph::fusion {

using skeleton::JointId;
using skeleton::kInferred;
using skeleton::kJointCount;
using skeleton::kTracked;
using Eigen::Vector3d;

const std::vector<std::string>& method_names() {
  static const std::vector<std::string> n{"avg", "sum", "facing", "weighted", "kalman"};
  return n;
}

std::optional<Method> method_from_name(std::string_view name) {
  const auto& n = method_names();
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (n[i] == name) return static_cast<Method>(i);
  }
  return std::nullopt;
}

const char* method_name(Method m) { return method_names()[static_cast<std::size_t>(m)].c_str(); }

namespace {

constexpr std::size_t kHistory = 4;          // samples kept per stream (enough to interpolate behind)
constexpr double kGate = 16.27;              // chi-square, 3 dof, 99.9 %
constexpr int kResetAfterMisses = 5;         // all measurements gated this often in a row: start over
constexpr std::int64_t kCoastNs = 200'000'000;  // a filtered joint without measurements stays "inferred" this long
constexpr std::int64_t kSettledNs = 1'000'000'000;  // a tracker's fresh skeleton is tens of centimetres off this long
// Evidence for a heading (facing_evidence), log-odds per frame: the fused neck over kLeanAt in front of the
// hips; a pair of views (in front, behind) whose recent arm confidences differ by over the margin. Kept with
// this memory per frame (30 Hz: about 3 s), at most kBeliefMax; the heading turned round below -kReverseAt.
constexpr double kLeanAt = 0.15, kLeanWeight = 0.3;
// People walk forwards: torso moving at kWalkAt m/s or faster (horizontal,
// smoothed over about 0.3 s), within 60 degrees of a heading or its reverse,
// is this much evidence for that one.
constexpr double kWalkAt = 0.35, kWalkWeight = 0.3, kWalkMemory = 0.9;
constexpr double kConfWeight = 0.5, kConfMargin = 0.02;
constexpr double kBeliefMemory = 0.99, kBeliefMax = 10.0, kReverseAt = 3.0;
constexpr double kArmMemory = 0.97;
// A tracker that lost its person may go on reporting the last skeleton for
// seconds (NITE: 2.5 s and more, sliding onto a wall): the same shape frame
// after frame, where a tracked person's joints always move against each
// other by the depth noise. kFrozenFrames samples in a row whose joints moved
// under kFrozenM (RMS, about the torso) make the stream frozen (kalman).
constexpr int kFrozenFrames = 4;
constexpr double kApart = 0.3;
constexpr double kStickM = 0.15;  // a stream's own person counts this much nearer (associate)
constexpr std::int64_t kPredictNs = 300'000'000;  // m between two skeletons' centres: beyond any tracker noise
constexpr double kFrozenM = 0.002;
// Per joint (JointId order), the SD (m, per axis) of the trackers' error that
// neither the filter nor the sensors' spread shows: where a tracker puts a
// joint against where it is (its joint definitions, its slow biases), shared
// by the sensors and steady over time. Fitted once on the simulator (seed 1;
// walk, 360 and arms; two sensors, NITE model): 0.42 x each joint's mean
// kalman error there, the factor that put 95 % of those joint-ticks inside
// their 95 % region; legs, not scored, take the hip like the torso and the
// foot like the hand. docs/experiments/2026-12-04-uncertainty.md checks it
// on seeds, layouts, heights and scenarios it was not fitted on.
constexpr double kBiasSdM[kJointCount] = {0.035, 0.018, 0.032, 0.028, 0.031, 0.051, 0.028, 0.031,
                                           0.051, 0.032, 0.038, 0.051, 0.032, 0.038, 0.051};  // the arm confidence of a stream, averaged over about a second

struct Sample {
  std::int64_t t;
  skeleton::Skeleton world;
};

struct Stream {
  std::size_t sensor;
  std::int64_t first_ns = 0;  // its first sample: a tracker's fresh skeleton is still settling
  double arm_confidence = 1.0;  // mean confidence of its arm joints, lately (kArmMemory)
  int still = 0;                // samples in a row whose shape did not change (kFrozenM)
  int parked = 0;               // ... nor its place (the torso moved under kFrozenM)
  bool frozen() const { return still >= kFrozenFrames; }
  bool parked_ghost() const { return parked >= kFrozenFrames; }
  std::deque<Sample> samples;
  std::optional<std::uint32_t> track;
};

struct SensorInfo {
  std::string id;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  bool has_pose = false;
  std::int64_t last_ns = std::numeric_limits<std::int64_t>::min();
  // Its clock against ours: the least (arrival - stamp) over the current and
  // the previous window of kShiftWindow, i.e. the shift that makes its
  // quickest delivery lately take no time. Stamp + shift is the capture time
  // on our clock, late by at most that quickest delivery (a hop: well under a
  // millisecond on a LAN); the windows follow a drifting clock.
  std::int64_t shift_now = std::numeric_limits<std::int64_t>::max();
  std::int64_t shift_before = std::numeric_limits<std::int64_t>::max();
  std::int64_t shift_window_ns = std::numeric_limits<std::int64_t>::min();
  std::int64_t capture_latency_ns = 0;  // the tracker's own delay: its skeleton shows the body this long before its stamp
  std::int64_t capture_ns(std::int64_t stamp_ns, bool shared_clock) const {
    const auto shift = shared_clock ? 0 : std::min(shift_now, shift_before);
    return (shift == std::numeric_limits<std::int64_t>::max() ? stamp_ns : stamp_ns + shift) - capture_latency_ns;
  }
};
constexpr std::int64_t kShiftWindow = 10'000'000'000;

struct View {
  Stream* stream;
  std::size_t sensor;
  skeleton::Skeleton s;
  Vector3d centre;
  double facing = 0;     // cos of the angle between the person's heading and the way to the sensor
  double conf_sum = 0;
  bool flipped = false;
  bool occluded = false;  // kalman: probably on an occluder in front of the person (see mark_occluded)
};

struct Bone {
  JointId parent, child;
};
constexpr Bone kLimbs[] = {{JointId::LeftShoulder, JointId::LeftElbow},   {JointId::LeftElbow, JointId::LeftHand},
                           {JointId::RightShoulder, JointId::RightElbow}, {JointId::RightElbow, JointId::RightHand},
                           {JointId::Neck, JointId::Head}};

struct Track {
  std::uint32_t id = 0;
  std::int64_t last_ns = 0;
  Vector3d centre = Vector3d::Zero();
  Vector3d velocity = Vector3d::Zero();  // of the centre, horizontal, smoothed (kWalkMemory)
  std::optional<Vector3d> heading;  // horizontal unit vector the torso faces
  double heading_belief = 0;        // evidence for the heading over its reverse (log-odds; negative: against it)
  std::array<JointFilter, kJointCount> filters;
  std::array<int, kJointCount> misses{};
  std::array<std::int64_t, kJointCount> last_update_ns{};
  // Per joint, what the latest instant's measurements say about the
  // uncertainty that the filter's own covariance, averaging them over time
  // as if independent, leaves out (their errors are correlated over time:
  // the trackers' offsets and slowly wandering bias): their variance
  // combined (1 / sum of 1/sigma^2) and how far apart they are (their
  // 1/sigma^2-weighted spread about the estimate), m^2.
  std::array<Eigen::Matrix3d, kJointCount> instant_cov = zero_covariances();
  static std::array<Eigen::Matrix3d, kJointCount> zero_covariances() {
    std::array<Eigen::Matrix3d, kJointCount> z;
    z.fill(Eigen::Matrix3d::Zero());
    return z;
  }
  std::array<double, std::size(kLimbs)> bone_sum{}, bone_n{};
  skeleton::Skeleton last;  // last output
  std::uint64_t frames = 0;
};

// RMS over the joints both skeletons have of how far each moved relative to
// the torso: 0 for the same shape however the whole moved.
double shape_change(const skeleton::Skeleton& a, const skeleton::Skeleton& b) {
  const auto& ta = a[JointId::Torso];
  const auto& tb = b[JointId::Torso];
  if (ta.confidence <= 0 || tb.confidence <= 0) return std::numeric_limits<double>::infinity();
  double sum = 0;
  int n = 0;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    if (a.joints[j].confidence <= 0 || b.joints[j].confidence <= 0) continue;
    sum += ((a.joints[j].position - ta.position) - (b.joints[j].position - tb.position)).squaredNorm();
    ++n;
  }
  return n > 1 ? std::sqrt(sum / (n - 1)) : std::numeric_limits<double>::infinity();
}

// The way the torso faces, from the shoulders as this view labels them (horizontal, unit), if it has them.
std::optional<Vector3d> claimed_heading(const skeleton::Skeleton& s) { return skeleton::claimed_facing(s, Vector3d::UnitY()); }

}  // namespace

struct Fuser::Impl {
  FuserOptions opt;
  FuserStats stats;
  std::vector<SensorInfo> sensors;
  std::map<std::pair<std::size_t, std::uint32_t>, Stream> streams;  // (sensor, raw person id)
  std::vector<Track> tracks;
  std::uint32_t next_track_id = 1;
  std::uint64_t frame_number = 0;
  std::vector<std::uint32_t> ended;     // tracks that lost a stream by remove(): gone if none is left
  std::vector<std::uint32_t> departed;  // fused people forgotten since take_departed()

  std::size_t sensor_index(const std::string& id) {
    for (std::size_t i = 0; i < sensors.size(); ++i) {
      if (sensors[i].id == id) return i;
    }
    sensors.push_back({id});
    sensors.back().capture_latency_ns = opt.capture_latency_ns;
    return sensors.size() - 1;
  }

  Vector3d sensor_position(std::size_t i) const { return sensors[i].pose.translation(); }

  // The stream's skeleton at t: interpolated between the samples around t when
  // both exist, else the latest before t if it is recent enough.
  std::optional<skeleton::Skeleton> view_at(const Stream& st, std::int64_t t) const {
    const Sample* before = nullptr;
    const Sample* after = nullptr;
    for (const auto& s : st.samples) {
      if (s.t <= t) before = &s;
      else if (after == nullptr) after = &s;
    }
    if (before == nullptr || t - before->t > opt.max_age_ns) return std::nullopt;
    if (!opt.interpolate || after == nullptr || before->t == t) return before->world;
    const double a = static_cast<double>(t - before->t) / static_cast<double>(after->t - before->t);
    skeleton::Skeleton s = before->world;
    s.stamp_ns = before->world.stamp_ns + std::llround(a * static_cast<double>(after->world.stamp_ns - before->world.stamp_ns));
    for (std::size_t j = 0; j < kJointCount; ++j) {
      const auto& b = before->world.joints[j];
      const auto& c = after->world.joints[j];
      if (b.confidence <= 0 || c.confidence <= 0) continue;  // a joint that appears or vanishes is not blended
      s.joints[j].position = (1 - a) * b.position + a * c.position;
      s.joints[j].confidence = std::min(b.confidence, c.confidence);
    }
    return s;
  }

  Track& track_by_id(std::uint32_t id) {
    return *std::find_if(tracks.begin(), tracks.end(), [&](const Track& t) { return t.id == id; });
  }
  bool has_track(std::uint32_t id) const {
    return std::any_of(tracks.begin(), tracks.end(), [&](const Track& t) { return t.id == id; });
  }

  // Where the person is expected at t: the last place moved on by the
  // walking velocity (for at most kPredictNs).
  static Vector3d predicted_centre(const Track& tr, std::int64_t t) {
    const double dt = static_cast<double>(std::clamp<std::int64_t>(t - tr.last_ns, 0, kPredictNs)) * 1e-9;
    return tr.centre + dt * tr.velocity;
  }

  // Assigns each view to a fused person: the one whose predicted place is
  // nearest among those near enough (its stream's own person counting a
  // little nearer), else, for a new stream, the nearest without a view from
  // the same sensor, else a new one.
  std::map<std::uint32_t, std::vector<View*>> associate(std::vector<View>& views, std::int64_t t) {
    std::map<std::uint32_t, std::vector<View*>> by_track;
    auto taken = [&](std::uint32_t id, std::size_t sensor) {
      const auto it = by_track.find(id);
      return it != by_track.end() &&
             std::any_of(it->second.begin(), it->second.end(), [&](const View* v) { return v->sensor == sensor; });
    };
    std::vector<View*> open;
    for (auto& v : views) {
      auto& bound = v.stream->track;
      // Two tracks of one person (the sensors' first skeletons disagreed):
      // the stream moves to the older track where it is, and the younger one,
      // left without streams, is gone at the next step (else it would stay a
      // second person until it timed out). Fused ids stay those of the first track.
      if (bound && has_track(*bound)) {
        for (const auto& tr : tracks) {
          if (tr.id < *bound && !taken(tr.id, v.sensor) && (tr.centre - v.centre).norm() < 0.5 * opt.match_distance_m &&
              (track_by_id(*bound).centre - tr.centre).norm() < 0.5 * opt.match_distance_m) {
            ended.push_back(*bound);  // left without a stream, the younger one is gone at the next step
            bound = tr.id;
            ++stats.tracks_merged;
            break;
          }
        }
      }
    }
    // Views of streams that belong to someone go to the person whose
    // predicted place is nearest, one view per sensor and person, the closest
    // pairs first; its own person counts kStickM nearer and may be up to
    // twice match_distance_m away, another at most match_distance_m, and only
    // once its own is kApart or more away: a tracker's ids are kept unless
    // another person is clearly nearer (trackers swap ids when people pass
    // close to each other).
    struct Candidate {
      View* v;
      std::uint32_t track;
      double cost;
    };
    std::vector<Candidate> candidates;
    for (auto& v : views) {
      const auto& bound = v.stream->track;
      if (!bound || !has_track(*bound)) continue;
      const double d_own = (predicted_centre(track_by_id(*bound), t) - v.centre).norm();
      for (const auto& tr : tracks) {
        const bool own = tr.id == *bound;
        const double d = own ? d_own : (predicted_centre(tr, t) - v.centre).norm();
        if (own ? d < 2 * opt.match_distance_m : d < opt.match_distance_m && d_own >= kApart)
          candidates.push_back({&v, tr.id, own ? d - kStickM : d});
      }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
    std::set<const View*> placed;
    for (const auto& c : candidates) {
      if (placed.count(c.v) > 0 || taken(c.track, c.v->sensor)) continue;
      c.v->stream->track = c.track;
      by_track[c.track].push_back(c.v);
      placed.insert(c.v);
    }
    for (auto& v : views) {
      if (placed.count(&v) == 0) open.push_back(&v);
    }
    // Each person's views in the order of the streams, new streams' after
    // (the heading's first claim is the first view's).
    for (auto& [id, vs] : by_track) std::sort(vs.begin(), vs.end());
    for (View* v : open) {
      Track* best = nullptr;
      // A tracker's fresh skeleton is tens of centimetres off, more when it
      // slides back from where it lost the person: it may join from further.
      double best_d = t - v->stream->first_ns < kSettledNs ? 2 * opt.match_distance_m : opt.match_distance_m;
      for (auto& tr : tracks) {
        if (taken(tr.id, v->sensor)) continue;
        // Compare with where the person is now if another sensor already placed it this round.
        Vector3d c = tr.centre;
        const auto it = by_track.find(tr.id);
        if (it != by_track.end() && !it->second.empty()) c = it->second.front()->centre;
        const double d = (c - v->centre).norm();
        if (d < best_d) {
          best_d = d;
          best = &tr;
        }
      }
      if (best == nullptr) {
        Track nt;
        nt.id = next_track_id++;
        nt.centre = v->centre;
        nt.last_ns = t;
        tracks.push_back(std::move(nt));
        best = &tracks.back();
      }
      v->stream->track = best->id;
      by_track[best->id].push_back(v);
    }
    return by_track;
  }

  // A frozen view stays with the person its stream belonged to, left out (as
  // a ghost on an occluder is) when the other sensors place that person
  // kApart or more from it; otherwise it joins the nearest person without a
  // view of its sensor within kApart of where they are now, or none.
  void join_if_in_place(View& v, std::map<std::uint32_t, std::vector<View*>>& by_track) {
    const auto has_sensor = [&](const std::vector<View*>& vs) {
      return std::any_of(vs.begin(), vs.end(), [&](const View* u) { return u->sensor == v.sensor; });
    };
    if (v.stream->track && has_track(*v.stream->track)) {
      auto& vs = by_track[*v.stream->track];
      if (!has_sensor(vs)) {
        if (!vs.empty() && (vs.front()->centre - v.centre).norm() >= kApart) {
          v.occluded = true;
          ++stats.ghost_views;
        }
        vs.push_back(&v);
        return;
      }
    }
    Track* best = nullptr;
    double best_d = kApart;
    for (auto& tr : tracks) {
      const auto it = by_track.find(tr.id);
      const bool here = it != by_track.end() && !it->second.empty();
      if (here && has_sensor(it->second)) continue;
      const Vector3d c = here ? it->second.front()->centre : tr.centre;
      const double d = (c - v.centre).norm();
      if (d < best_d) {
        best_d = d;
        best = &tr;
      }
    }
    if (best == nullptr) {
      ++stats.ghost_views;
      return;
    }
    v.stream->track = best->id;
    by_track[best->id].push_back(&v);
  }

  // Evidence that the person faces `h` rather than the reverse (a log-odds),
  // from one moment's views. Which way a view labels left and right says
  // little: every tracker assumes the person faces it and mirrors them when
  // it sees their back, so with sensors on opposite sides both headings
  // explain the labels (without such a pair, as with the thesis's two
  // sensors 90 degrees apart, the labels do tell: no evidence is needed and
  // none is given). Two things do tell:
  //  - a person bent over (picking something up, sitting down) leans
  //    forwards: the fused neck well in front of the hips (labels do not
  //    matter); while so, nothing else counts (hands on an object are
  //    reported less surely from the front, which would mislead the next);
  //  - a tracker is surer of the arms it sees from the front: of two views,
  //    one in front of the person and one behind by `h`, the one in front
  //    should have reported the arms at confidence 1 more often lately.
  // Fresh skeletons (under a second old) are tens of centimetres off: not counted.
  double facing_evidence(const Vector3d& h, const std::vector<View*>& vs, std::int64_t t, const Track& tr) const {
    const auto settled = [&](const View* v) { return t - v->stream->first_ns >= kSettledNs && !v->occluded; };
    const auto way = [&](const View* v) {
      Vector3d u = sensor_position(v->sensor) - v->centre;
      u.y() = 0;
      return u.norm() > 1e-6 ? Vector3d(u.normalized()) : Vector3d::Zero();
    };
    bool opposite = false;
    for (const View* a : vs) {
      for (const View* b : vs) opposite = opposite || (settled(a) && settled(b) && way(a).dot(way(b)) < -0.5);
    }
    if (!opposite) return 0;
    double e = 0;
    if (tr.velocity.norm() >= kWalkAt) {
      const double c = tr.velocity.normalized().dot(h);
      if (std::abs(c) >= 0.5) e += c > 0 ? kWalkWeight : -kWalkWeight;
    }
    if (tr.frames > 0) {
      Vector3d lean = tr.last[JointId::Neck].position -
                      0.5 * (tr.last[JointId::LeftHip].position + tr.last[JointId::RightHip].position);
      lean.y() = 0;
      if (lean.norm() > kLeanAt) return e + (lean.dot(h) > 0 ? kLeanWeight : -kLeanWeight);
    }
    for (const View* a : vs) {
      if (!settled(a) || h.dot(way(a)) < 0.3) continue;  // a: in front of the person, by h
      for (const View* b : vs) {
        if (!settled(b) || h.dot(way(b)) > -0.3) continue;  // b: behind
        const double d = a->stream->arm_confidence - b->stream->arm_confidence;
        if (std::abs(d) > kConfMargin) e += d > 0 ? kConfWeight : -kConfWeight;
      }
    }
    return e;
  }

  // Heading of the person and, against it, which views see the back (their
  // left and right swapped). The heading starts once the views agree on it,
  // or one heading explains them best (disputed_heading).
  void update_heading(Track& tr, std::vector<View*>& vs, bool correct_flips, std::int64_t t) {
    std::vector<std::pair<View*, Vector3d>> claims;
    for (View* v : vs) {
      if (v->occluded) continue;  // a ghost on an occluder says nothing about where the person faces
      if (auto f = claimed_heading(v->s)) claims.emplace_back(v, *f);
    }
    if (!tr.heading) {
      bool agree = !claims.empty();
      for (std::size_t i = 0; i < claims.size(); ++i) {
        for (std::size_t k = i + 1; k < claims.size(); ++k) agree = agree && claims[i].second.dot(claims[k].second) > 0;
      }
      if (agree) {
        Vector3d sum = Vector3d::Zero();
        for (const auto& c : claims) sum += c.second;
        if (sum.norm() > 1e-6) tr.heading = sum.normalized();
      } else if (!claims.empty()) {
        // The views disagree (one behind the person mirrors them): the claim,
        // or claim reversed, the evidence favours (the first claim when none).
        double best = -std::numeric_limits<double>::infinity();
        for (const auto& [v, c] : claims) {
          for (const double sign : {1.0, -1.0}) {
            const double e = facing_evidence(sign * c, vs, t, tr);
            if (e > best + 1e-9) {
              best = e;
              tr.heading = sign * c;
            }
          }
        }
      }
    } else {
      // The evidence for the heading, with a memory of a few seconds; a
      // heading it holds against (taken from mirrored views: a sensor behind
      // the person saw them first) is turned round.
      tr.heading_belief = std::clamp(kBeliefMemory * tr.heading_belief + facing_evidence(*tr.heading, vs, t, tr),
                                     -kBeliefMax, kBeliefMax);
      if (tr.heading_belief <= -kReverseAt) {
        tr.heading = -*tr.heading;
        tr.heading_belief = -tr.heading_belief;
        ++stats.headings_reversed;
      }
      Vector3d sum = Vector3d::Zero();
      for (auto& [v, f] : claims) {
        if (f.dot(*tr.heading) < -0.2) {  // this sensor sees the back and labels it as the front
          v->flipped = true;
          f = -f;
          if (correct_flips) {
            skeleton::swap_sides(v->s);
            ++stats.flips_corrected;
          }
        }
        sum += f;
      }
      if (sum.norm() > 1e-6) tr.heading = (0.7 * *tr.heading + 0.3 * sum.normalized()).normalized();
    }
    for (View* v : vs) {
      Vector3d to_sensor = sensor_position(v->sensor) - v->centre;
      to_sensor.y() = 0;
      const auto own = claimed_heading(v->s);
      const Vector3d h = tr.heading ? *tr.heading : (own ? *own : Vector3d::Zero());
      v->facing = to_sensor.norm() > 1e-6 ? h.dot(to_sensor.normalized()) : 0.0;
      v->conf_sum = 0;
      for (const auto& j : v->s.joints) v->conf_sum += j.confidence;
    }
  }

  // One joint by a selection/averaging method. Returns false when no view reports it.
  bool fuse_joint_simple(Method m, std::size_t j, const std::vector<View*>& vs, skeleton::Joint& out) {
    for (const float level : {kTracked, kInferred}) {
      std::vector<const View*> cand;
      for (const View* v : vs) {
        if (v->s.joints[j].confidence >= level) cand.push_back(v);
      }
      if (cand.empty()) continue;
      out.confidence = level;
      out.sensor_mask = 0;
      if (m == Method::Avg) {
        Vector3d sum = Vector3d::Zero();
        for (const View* v : cand) {
          sum += v->s.joints[j].position;
          out.sensor_mask |= 1u << v->sensor;
        }
        out.position = sum / static_cast<double>(cand.size());
      } else if (m == Method::Weighted) {
        Vector3d sum = Vector3d::Zero();
        double wsum = 0;
        std::vector<std::pair<const View*, double>> used;  // with its weight
        for (const View* v : vs) {
          const auto& jj = v->s.joints[j];
          if (jj.confidence < kInferred) continue;
          const double d = std::max(0.5, (jj.position - sensor_position(v->sensor)).norm());
          const double w = (jj.confidence >= kTracked ? 1.0 : 0.15) * (0.25 + 0.75 * (v->facing + 1) / 2) / (d * d);
          sum += w * jj.position;
          wsum += w;
          used.emplace_back(v, w);
          out.sensor_mask |= 1u << v->sensor;
        }
        out.position = sum / wsum;
        // Uncertainty: how far apart the views are (their weighted spread about the
        // result) plus the measurement model's variance of the views combined.
        Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
        double info = 0;
        for (const auto& [v, w] : used) {
          const Vector3d e = v->s.joints[j].position - out.position;
          spread += w * e * e.transpose();
          const double s = measurement_sigma(*v, j);
          info += 1.0 / (s * s);
        }
        const double bias = opt.bias_sd_scale * kBiasSdM[j];
        skeleton::set_covariance(out, spread / wsum + Eigen::Matrix3d::Identity() * (1.0 / info + bias * bias));
      } else {
        const auto score = [&](const View* v) { return m == Method::Sum ? v->conf_sum : v->facing; };
        const View* best = *std::max_element(cand.begin(), cand.end(),
                                             [&](const View* a, const View* b) { return score(a) < score(b); });
        out.position = best->s.joints[j].position;
        out.sensor_mask = 1u << best->sensor;
      }
      return true;
    }
    return false;
  }

  // Depth sensors cannot see through things: a view whose skeleton is far
  // from another sensor's, with that other skeleton behind it along this
  // sensor's line of sight, is explained by this sensor seeing something in
  // front of the person (a partition, a box: where a tracker that lost the
  // person leaves its ghost), and the person hidden behind it. The other way
  // round it is not: the other sensor would be reporting a person where its
  // own depth image shows free space. Such a view is left out while the two
  // disagree; with no clear answer (both or neither) nothing is left out, nor
  // while either stream is under a second old (a tracker that has just found
  // someone places them tens of centimetres off for a while, either way).
  void mark_occluded(std::vector<View*>& vs, std::int64_t t) {
    const auto settled = [&](const View& v) { return t - v.stream->first_ns >= kSettledNs; };
    const auto behind = [&](const View& v, const View& u) {  // u hidden behind v from v's sensor
      const Vector3d ray = (v.centre - sensor_position(v.sensor)).normalized();
      const Vector3d o = u.centre - v.centre;
      const double along = o.dot(ray);
      return along > 0.5 * kApart && (o - along * ray).norm() < along;  // within 45 degrees of the ray
    };
    // Two passes, so the answer does not depend on the views' order: a view
    // is left out when a sensor that is not itself suspect vouches against it.
    const auto against = [&](const View& v, const View& u) {
      return &u != &v && u.sensor != v.sensor && settled(u) && settled(v) && (u.centre - v.centre).norm() >= kApart &&
             behind(v, u) && !behind(u, v);
    };
    std::vector<bool> suspect(vs.size(), false);
    for (std::size_t a = 0; a < vs.size(); ++a) {
      for (std::size_t b = 0; b < vs.size(); ++b) suspect[a] = suspect[a] || against(*vs[a], *vs[b]);
    }
    for (std::size_t a = 0; a < vs.size(); ++a) {
      for (std::size_t b = 0; b < vs.size(); ++b) {
        if (!suspect[b] && !vs[b]->occluded && against(*vs[a], *vs[b])) vs[a]->occluded = true;
      }
    }
    for (const View* v : vs) stats.occluded_views += v->occluded ? 1 : 0;
  }

  double measurement_sigma(const View& v, std::size_t j) const {
    const auto& jj = v.s.joints[j];
    const double d = (jj.position - sensor_position(v.sensor)).norm();
    const double dist = 0.5 + 0.5 * (d / 2.0) * (d / 2.0);   // depth noise grows with the square of range
    const double view = 1.0 + 0.75 * (1.0 - v.facing);        // seen from the side or behind: less sure
    const double conf = jj.confidence >= kTracked ? 1.0 : 3.0;
    return 0.03 * dist * view * conf;
  }

  void fuse_kalman(Track& tr, const std::vector<View*>& vs, std::int64_t t, skeleton::Skeleton& out) {
    const bool arbitrated = std::any_of(vs.begin(), vs.end(), [](const View* v) { return v->occluded; });
    for (std::size_t j = 0; j < kJointCount; ++j) {
      auto& f = tr.filters[j];
      auto& oj = out.joints[j];
      std::vector<std::pair<const View*, double>> meas;
      for (const View* v : vs) {
        if (!v->occluded && v->s.joints[j].confidence >= kInferred) meas.emplace_back(v, measurement_sigma(*v, j));
      }
      bool tracked = false, any = false;
      std::vector<std::pair<Vector3d, double>> used;  // the measurements used this step, with their sigma
      // Every sensor's measurement fell outside the gate, but two or more of
      // them agree with each other: it is the filter that is off (a fast
      // movement its constant velocity did not follow), not the sensors.
      bool agree = true;  // every pair of sensors within the gate of each other
      for (std::size_t a = 0; agree && a < meas.size(); ++a) {
        for (std::size_t b = a + 1; agree && b < meas.size(); ++b) {
          const double sa = meas[a].second, sb = meas[b].second;
          const double d = (meas[a].first->s.joints[j].position - meas[b].first->s.joints[j].position).norm();
          agree = d * d <= kGate * (sa * sa + sb * sb);
        }
      }
      // With a view left out, has the filter been following it (nearer to its
      // joint than to every remaining sensor's)? Then the rest start it over
      // at once; otherwise a remaining sensor's outlier is gated as usual.
      bool followed_left_out = false;
      if (arbitrated && f.initialised() && !meas.empty()) {
        double nearest_kept = std::numeric_limits<double>::infinity();
        for (const auto& [v, sg] : meas) nearest_kept = std::min(nearest_kept, (v->s.joints[j].position - f.position()).norm());
        for (const View* v : vs) {
          if (v->occluded && v->s.joints[j].confidence >= kInferred)
            followed_left_out = followed_left_out || (v->s.joints[j].position - f.position()).norm() < nearest_kept;
        }
      }
      bool sensors_agree_against_filter = false;
      if (f.initialised() && (meas.size() >= 2 || followed_left_out) && tr.misses[j] < kResetAfterMisses && agree) {
        bool all_gated = true;
        for (const auto& [v, sg] : meas) all_gated = all_gated && f.mahalanobis2(v->s.joints[j].position, sg) > kGate;
        sensors_agree_against_filter = all_gated;
      }
      if (!meas.empty() && (!f.initialised() || tr.misses[j] >= kResetAfterMisses || sensors_agree_against_filter)) {
        // Start from the confidence-weighted mean of what the sensors say when
        // they agree; when they do not, from the most trusted one alone (a mean
        // of two places is neither, and the filter would then run off towards
        // one of them with a velocity it never had).
        Vector3d sum = Vector3d::Zero();
        double wsum = 0, sig = 0;
        const auto best = std::min_element(meas.begin(), meas.end(),
                                           [](const auto& a, const auto& b) { return a.second < b.second; });
        for (const auto& [v, s] : meas) {
          if (!agree && v != best->first) continue;
          const double w = 1.0 / (s * s);
          sum += w * v->s.joints[j].position;
          wsum += w;
          used.emplace_back(v->s.joints[j].position, s);
          sig = std::max(sig, s);
          oj.sensor_mask |= 1u << v->sensor;
          tracked = tracked || v->s.joints[j].confidence >= kTracked;
        }
        f.reset(sum / wsum, sig, t);
        tr.misses[j] = 0;
        tr.last_update_ns[j] = t;
        any = true;
      } else if (f.initialised()) {
        f.predict(t);
        for (const auto& [v, s] : meas) {
          const Vector3d z = v->s.joints[j].position;
          if (f.mahalanobis2(z, s) > kGate) {
            ++stats.gated;
            continue;
          }
          f.update(z, s);
          used.emplace_back(z, s);
          oj.sensor_mask |= 1u << v->sensor;
          tracked = tracked || v->s.joints[j].confidence >= kTracked;
          any = true;
        }
        if (any) {
          tr.misses[j] = 0;
          tr.last_update_ns[j] = t;
        } else if (!meas.empty()) {
          ++tr.misses[j];
        }
      }
      if (!f.initialised()) continue;
      JointFilter ahead = f;  // the output: the state now, or predicted to the moment of use
      if (opt.predict_ns > 0) ahead.predict(t + opt.predict_ns);
      oj.position = ahead.position();
      // Published uncertainty: the filter's covariance plus what the latest measurements cannot average away.
      if (!used.empty()) {
        Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
        double info = 0;
        for (const auto& [z, s] : used) {
          const Vector3d e = z - f.position();
          spread += e * e.transpose() / (s * s);
          info += 1.0 / (s * s);
        }
        tr.instant_cov[j] = (spread + Eigen::Matrix3d::Identity()) / info;
      }
      const double bias = opt.bias_sd_scale * kBiasSdM[j];
      skeleton::set_covariance(oj, ahead.position_covariance() + tr.instant_cov[j] +
                                       Eigen::Matrix3d::Identity() * (bias * bias));
      oj.confidence = tracked ? kTracked : (any || t - tr.last_update_ns[j] <= kCoastNs ? kInferred : 0.0f);
    }
    // Limbs keep their length: learn each from confident frames, then pull the child towards it.
    for (std::size_t b = 0; b < std::size(kLimbs); ++b) {
      const auto p = static_cast<std::size_t>(kLimbs[b].parent), c = static_cast<std::size_t>(kLimbs[b].child);
      if (out.joints[p].confidence < kTracked || out.joints[c].confidence <= 0) continue;
      const Vector3d d = out.joints[c].position - out.joints[p].position;
      const double len = d.norm();
      if (len < 1e-6) continue;
      if (out.joints[c].confidence >= kTracked && tr.bone_n[b] < 300) {
        tr.bone_sum[b] += len;
        tr.bone_n[b] += 1;
      }
      if (tr.bone_n[b] < 15) continue;
      const double target = tr.bone_sum[b] / tr.bone_n[b];
      const Vector3d moved = out.joints[p].position + d * ((0.5 * len + 0.5 * target) / len);
      out.joints[c].position = moved;
      tr.filters[c].set_position(moved);
    }
  }

  std::vector<skeleton::Skeleton> fuse(std::int64_t now) {
    const std::int64_t t = now - opt.delay_ns;
    // Forget streams and people that went quiet.
    for (auto it = streams.begin(); it != streams.end();) {
      if (it->second.samples.empty() || t - it->second.samples.back().t > opt.person_timeout_ns) it = streams.erase(it);
      else ++it;
    }
    // A person whose every sensor said it lost them is gone at once; one
    // nobody has reported for a while is forgotten.
    for (const auto id : ended) {
      const bool fed = std::any_of(streams.begin(), streams.end(),
                                   [&](const auto& kv) { return kv.second.track && *kv.second.track == id; });
      if (fed) continue;
      for (auto& tr : tracks) {
        if (tr.id == id) tr.last_ns = std::numeric_limits<std::int64_t>::min() / 2;
      }
    }
    ended.clear();
    tracks.erase(std::remove_if(tracks.begin(), tracks.end(),
                                [&](const Track& tr) {
                                  if (t - tr.last_ns <= opt.person_timeout_ns) return false;
                                  departed.push_back(tr.id);
                                  return true;
                                }),
                 tracks.end());
    std::vector<View> views;
    for (auto& [key, st] : streams) {
      auto s = view_at(st, t);
      if (!s) continue;
      const auto c = skeleton::centre_of(*s);
      if (!c) continue;
      views.push_back({&st, key.first, std::move(*s), *c});
    }
    // kalman: frozen streams (a tracker's ghost of a person it lost) start
    // no person and count only where the other sensors still place their
    // person (else the person walked on: the frozen skeleton is left behind).
    // When every view is frozen (a still scene without tracker noise, as a
    // synthetic one), that says nothing: they are all used as they are.
    std::vector<View> frozen;
    const bool any_live = std::any_of(views.begin(), views.end(), [](const View& v) { return !v.stream->frozen(); });
    if (opt.method == Method::Kalman && any_live) {
      for (auto it = views.begin(); it != views.end();) {
        if (it->stream->frozen()) {
          frozen.push_back(std::move(*it));
          it = views.erase(it);
        } else {
          ++it;
        }
      }
    }
    auto by_track = associate(views, t);
    for (auto& v : frozen) join_if_in_place(v, by_track);
    // A person whom only frozen skeletons standing in one place put there
    // (every live view lost them): the ghost says where they were, not where
    // they are (they walked on). Their filters coast on, the uncertainty
    // growing, and after kCoastNs their joints are unplaced (confidence 0): a
    // robot's monitor stops for a person fusion cannot place rather than
    // trust the ghost. (A tracker's live person is never that still: depth
    // noise moves every joint.)
    for (auto& [id, vs] : by_track) {
      if (!frozen.empty() && !vs.empty() &&
          std::all_of(vs.begin(), vs.end(), [](const View* v) { return v->stream->parked_ghost(); })) {
        for (View* v : vs) v->occluded = true;
      }
    }
    std::vector<skeleton::Skeleton> out;
    ++frame_number;
    for (auto& [id, vs] : by_track) {
      Track& tr = track_by_id(id);
      if (opt.method == Method::Kalman) mark_occluded(vs, t);
      update_heading(tr, vs, opt.method == Method::Kalman || opt.method == Method::Weighted, t);
      skeleton::Skeleton f;
      f.sensor_id = "fused";
      f.person_id = id;
      f.frame_id = "world";
      f.stamp_ns = t;
      f.frame_number = frame_number;
      if (opt.method == Method::Kalman) {
        fuse_kalman(tr, vs, t, f);
      } else {
        for (std::size_t j = 0; j < kJointCount; ++j) {
          if (!fuse_joint_simple(opt.method, j, vs, f.joints[j])) {
            f.joints[j].position = tr.last.joints[j].position;  // not seen: where it was, confidence 0
            f.joints[j].confidence = 0;
          }
        }
      }
      // Capture stamps of what it was made from (views left out as ghosts aside).
      for (const bool all : {false, true}) {
        for (const auto& v : vs) {
          if (v->occluded && !all) continue;
          const auto c = sensors[v->sensor].capture_ns(v->s.stamp_ns, opt.shared_clock);
          f.capture_oldest_ns = f.capture_oldest_ns == 0 ? c : std::min(f.capture_oldest_ns, c);
          f.capture_newest_ns = f.capture_newest_ns == 0 ? c : std::max(f.capture_newest_ns, c);
        }
        if (f.capture_oldest_ns != 0) break;
      }
      if (const auto c = skeleton::centre_of(f)) {
        if (tr.frames > 0 && t > tr.last_ns) {
          Vector3d v = (*c - tr.centre) / (static_cast<double>(t - tr.last_ns) * 1e-9);
          v.y() = 0;
          tr.velocity = kWalkMemory * tr.velocity + (1 - kWalkMemory) * v;
        }
        tr.centre = *c;
      }
      tr.last_ns = t;
      tr.last = f;
      ++tr.frames;
      ++stats.fused;
      out.push_back(std::move(f));
    }
    return out;
  }
};

Fuser::Fuser(FuserOptions options) : impl_(std::make_unique<Impl>()) { impl_->opt = options; }
Fuser::~Fuser() = default;
Fuser::Fuser(Fuser&&) noexcept = default;
Fuser& Fuser::operator=(Fuser&&) noexcept = default;

void Fuser::set_pose(const std::string& sensor, const Eigen::Isometry3d& world_from_sensor) {
  auto& s = impl_->sensors[impl_->sensor_index(sensor)];
  s.pose = world_from_sensor;
  s.has_pose = true;
}

void Fuser::set_capture_latency(const std::string& sensor, std::int64_t ns) {
  impl_->sensors[impl_->sensor_index(sensor)].capture_latency_ns = ns;
}

bool Fuser::has_pose(const std::string& sensor) const {
  return std::any_of(impl_->sensors.begin(), impl_->sensors.end(),
                     [&](const SensorInfo& s) { return s.id == sensor && s.has_pose; });
}

void Fuser::heartbeat(const std::string& sensor, std::int64_t t_ns) {
  auto& s = impl_->sensors[impl_->sensor_index(sensor)];
  s.last_ns = std::max(s.last_ns, t_ns);
}

void Fuser::add(const skeleton::Skeleton& raw, std::int64_t t_ns) {
  const auto i = impl_->sensor_index(raw.sensor_id);
  auto& sensor = impl_->sensors[i];
  sensor.last_ns = std::max(sensor.last_ns, t_ns);
  if (t_ns - sensor.shift_window_ns > kShiftWindow) {
    sensor.shift_before = sensor.shift_now;
    sensor.shift_now = t_ns - raw.stamp_ns;
    sensor.shift_window_ns = t_ns;
  } else {
    sensor.shift_now = std::min(sensor.shift_now, t_ns - raw.stamp_ns);
  }
  if (!sensor.has_pose) {
    ++impl_->stats.no_pose;
    return;
  }
  if (i >= 32) return;  // the joint mask has 32 bits
  Sample s{t_ns, raw};
  for (auto& j : s.world.joints) j.position = sensor.pose * j.position;
  s.world.frame_id = "world";
  auto& st = impl_->streams[{i, raw.person_id}];
  // A stream that is new, or back after a gap (a tracker that lost and found
  // the person under the same id), is settling from this sample on.
  if (st.samples.empty() || t_ns - st.samples.back().t > impl_->opt.max_age_ns) st.first_ns = t_ns;
  st.sensor = i;
  // Samples arrive in time order from one sensor; keep a few for interpolation.
  auto pos = std::upper_bound(st.samples.begin(), st.samples.end(), t_ns,
                              [](std::int64_t t, const Sample& x) { return t < x.t; });
  double arms = 0;
  for (const auto j : {JointId::LeftShoulder, JointId::LeftElbow, JointId::LeftHand, JointId::RightShoulder,
                       JointId::RightElbow, JointId::RightHand}) {
    arms += raw[j].confidence;
  }
  st.arm_confidence = kArmMemory * st.arm_confidence + (1 - kArmMemory) * arms / 6;
  if (!st.samples.empty() && pos == st.samples.end() && t_ns - st.samples.back().t <= impl_->opt.max_age_ns) {
    const auto& prev = st.samples.back().world;
    st.still = shape_change(prev, s.world) < kFrozenM ? st.still + 1 : 0;
    const bool stayed = (prev[JointId::Torso].position - s.world[JointId::Torso].position).norm() < kFrozenM;
    st.parked = st.still > 0 && stayed ? st.parked + 1 : 0;
  } else if (pos == st.samples.end()) {
    st.still = 0;
    st.parked = 0;
  }
  st.samples.insert(pos, std::move(s));
  while (st.samples.size() > kHistory) st.samples.pop_front();
  ++impl_->stats.added;
}

void Fuser::remove(const std::string& sensor, std::uint32_t person_id) {
  for (std::size_t i = 0; i < impl_->sensors.size(); ++i) {
    if (impl_->sensors[i].id != sensor) continue;
    const auto it = impl_->streams.find({i, person_id});
    if (it == impl_->streams.end()) return;
    if (it->second.track) impl_->ended.push_back(*it->second.track);
    impl_->streams.erase(it);
    ++impl_->stats.streams_ended;
    return;
  }
}

std::vector<std::uint32_t> Fuser::take_departed() { return std::exchange(impl_->departed, {}); }

std::vector<skeleton::Skeleton> Fuser::fuse(std::int64_t t_ns) { return impl_->fuse(t_ns); }

std::vector<std::string> Fuser::sensors() const {
  std::vector<std::string> out;
  for (const auto& s : impl_->sensors) out.push_back(s.id);
  return out;
}

std::vector<std::string> Fuser::silent_sensors(std::int64_t t_ns) const {
  std::vector<std::string> out;
  for (const auto& s : impl_->sensors) {
    if (s.last_ns != std::numeric_limits<std::int64_t>::min() && t_ns - s.last_ns > impl_->opt.sensor_timeout_ns) {
      out.push_back(s.id);
    }
  }
  return out;
}

const FuserStats& Fuser::stats() const { return impl_->stats; }
const FuserOptions& Fuser::options() const { return impl_->opt; }

}  // namespace skelgraph::fusion
