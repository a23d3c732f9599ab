#include "skelgraph/calib/skeleton_calib.hpp"
#include "skelgraph/skeleton/stats.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <random>

namespace skelgraph::calib {

using Eigen::Vector3d;
using skeleton::JointId;
using skeleton::Skeleton;

namespace {

const std::vector<JointId>& default_joints() {
  static const std::vector<JointId> j{JointId::Head,      JointId::Neck,          JointId::Torso,
                                      JointId::LeftShoulder, JointId::RightShoulder, JointId::LeftElbow,
                                      JointId::RightElbow,  JointId::LeftHand,      JointId::RightHand,
                                      JointId::LeftHip,     JointId::RightHip};
  return j;
}

bool tracked(const Skeleton& s, JointId j) {
  const auto& x = s[j];
  return x.confidence >= skeleton::kTracked && x.position.allFinite();
}

using Track = std::vector<const TimedSkeleton*>;  // one person of one sensor, in time order

std::map<std::uint32_t, Track> tracks_of(const std::vector<TimedSkeleton>& v) {
  std::map<std::uint32_t, Track> out;
  for (const auto& s : v) out[s.skeleton.person_id].push_back(&s);
  for (auto& [id, tr] : out) {
    std::stable_sort(tr.begin(), tr.end(), [](auto* a, auto* b) { return a->t_ns < b->t_ns; });
  }
  return out;
}

// The person at t, linearly interpolated between the frames around it (no
// further apart than max_gap); a joint is tracked only if it is in both.
std::optional<Skeleton> at(const Track& tr, std::int64_t t, std::int64_t max_gap) {
  auto it = std::lower_bound(tr.begin(), tr.end(), t, [](const TimedSkeleton* s, std::int64_t x) { return s->t_ns < x; });
  if (it != tr.end() && (*it)->t_ns == t) return (*it)->skeleton;
  if (it == tr.begin() || it == tr.end()) return std::nullopt;
  const TimedSkeleton* b = *it;
  const TimedSkeleton* a = *(it - 1);
  if (b->t_ns - a->t_ns > max_gap) return std::nullopt;
  const double u = static_cast<double>(t - a->t_ns) / static_cast<double>(b->t_ns - a->t_ns);
  Skeleton s = a->skeleton;
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    const auto& ja = a->skeleton.joints[j];
    const auto& jb = b->skeleton.joints[j];
    s.joints[j].position = (1 - u) * ja.position + u * jb.position;
    s.joints[j].confidence = std::min(ja.confidence, jb.confidence);
  }
  return s;
}

// One reference person-frame and what the other sensor saw at that moment.
struct Candidate {
  const Skeleton* ref;
  std::vector<Skeleton> others;
};

std::vector<Candidate> candidates(const std::vector<TimedSkeleton>& reference, const std::map<std::uint32_t, Track>& other,
                                  std::int64_t offset, std::int64_t max_gap) {
  std::vector<Candidate> out;
  for (const auto& r : reference) {
    Candidate c{&r.skeleton, {}};
    for (const auto& [id, tr] : other) {
      if (auto s = at(tr, r.t_ns - offset, max_gap)) c.others.push_back(std::move(*s));
    }
    if (!c.others.empty()) out.push_back(std::move(c));
  }
  return out;
}

// How one of the other sensor's skeletons fits a reference one under a pose,
// as seen or with its sides swapped.
struct Fit {
  std::size_t agree = 0;  // joints within the threshold
  double median_m = std::numeric_limits<double>::infinity();
  std::size_t other = 0;
  bool swapped = false;
};

// Which labelling of the other's skeleton the two sensors' places allow
// under `pose`. A tracker takes the person to face it (a view of the back
// claims the reverse facing), so each skeleton's claimed facing points
// towards its own sensor: the two agree as labelled when the other sensor is
// on that side of the chest too, and with the sides swapped when it is behind.
// Told by each skeleton on its own; 0: as labelled, 1: swapped, -1: either
// (a sensor near the chest's plane, or no shoulders), -2: the two disagree.
int expected_swap(const Skeleton& ref, const Skeleton& other, const Alignment& pose) {
  constexpr double kMargin = 0.7;  // |cos| of the angle to the chest's normal: 45 degrees or less from it
  const auto side = [](const Skeleton& s, const Vector3d& sensor) {
    const auto torso = s[JointId::Torso];
    const auto neck = s[JointId::Neck];
    if (torso.confidence <= 0 || neck.confidence <= 0) return -1;
    const auto f = skeleton::claimed_facing(s, neck.position - torso.position);
    const Vector3d d = sensor - torso.position;
    if (!f || d.norm() < 1e-6) return -1;
    const double c = f->dot(d) / d.norm();
    return c > kMargin ? 0 : c < -kMargin ? 1 : -1;
  };
  const int a = side(ref, pose.t);                                // the other sensor's origin, in the reference's frame
  const int b = side(other, Vector3d(-pose.R.transpose() * pose.t));  // the reference's origin, in the other's frame
  if (a < 0) return b;
  if (b < 0) return a;
  return a == b ? a : -2;
}

Fit fit_of(const Candidate& c, const Alignment& pose, const std::vector<JointId>& joints, double thr) {
  Fit best;
  std::vector<double> d;
  for (std::size_t o = 0; o < c.others.size(); ++o) {
    const int expected = expected_swap(*c.ref, c.others[o], pose);
    if (expected == -2) continue;
    for (const bool swapped : {false, true}) {
      if (expected >= 0 && swapped != (expected == 1)) continue;
      d.clear();
      std::size_t agree = 0;
      for (const auto j : joints) {
        const JointId oj = swapped ? skeleton::mirror(j) : j;
        if (!tracked(*c.ref, j) || !tracked(c.others[o], oj)) continue;
        const double e = (pose.apply(c.others[o][oj].position) - (*c.ref)[j].position).norm();
        d.push_back(e);
        agree += e <= thr ? 1 : 0;
      }
      if (d.size() < 3) continue;
      const double m = stats::upper_median(d);
      if (agree > best.agree || (agree == best.agree && m < best.median_m)) best = {agree, m, o, swapped};
    }
  }
  return best;
}

struct Pairs {
  std::vector<Vector3d> other, ref;
  std::vector<JointId> joint;
  std::vector<bool> swapped;
  std::size_t matched = 0, mirrored = 0;
};

// A match fitting better with the other's sides swapped: one of the two
// sensors sees the person's back and, assuming they face it, labelled their
// left as right. The joints are where they are; only the labels are swapped,
// so the pairs are made with the sides swapped back.
Pairs pair_up(const std::vector<Candidate>& cs, const Alignment& pose, const std::vector<JointId>& joints,
              const SkeletonCalibOptions& o) {
  Pairs p;
  for (const auto& c : cs) {
    const Fit f = fit_of(c, pose, joints, o.inlier_threshold_m);
    if (!(f.median_m <= o.match_median_m)) continue;
    ++p.matched;
    p.mirrored += f.swapped ? 1 : 0;
    for (const auto j : joints) {
      const JointId oj = f.swapped ? skeleton::mirror(j) : j;
      if (!tracked(*c.ref, j) || !tracked(c.others[f.other], oj)) continue;
      p.other.push_back(c.others[f.other][oj].position);
      p.ref.push_back((*c.ref)[j].position);
      p.joint.push_back(j);
      p.swapped.push_back(f.swapped);
    }
  }
  return p;
}

// Frame-level RANSAC: a pose from one frame's joints, scored on (a spread of) all frames.
Alignment propose(const std::vector<Candidate>& cs, const std::vector<JointId>& joints, const SkeletonCalibOptions& o) {
  std::vector<const Candidate*> scored;
  const std::size_t step = std::max<std::size_t>(1, cs.size() / std::max<std::size_t>(1, o.max_scored_frames));
  for (std::size_t i = 0; i < cs.size(); i += step) scored.push_back(&cs[i]);
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> pick(0, cs.size() - 1);
  Alignment best;
  std::size_t best_score = 0;
  double best_med = std::numeric_limits<double>::infinity();
  for (int h = 0; h < o.hypotheses; ++h) {
    const Candidate& c = cs[pick(rng)];
    const Skeleton& other = c.others[std::uniform_int_distribution<std::size_t>(0, c.others.size() - 1)(rng)];
    // The frame as labelled, and with the other's sides swapped (a view of the back).
    for (const bool swapped : {false, true}) {
      std::vector<Vector3d> a, b;
      for (const auto j : joints) {
        const JointId oj = swapped ? skeleton::mirror(j) : j;
        if (tracked(*c.ref, j) && tracked(other, oj)) a.push_back(other[oj].position), b.push_back((*c.ref)[j].position);
      }
      if (a.size() < 4) continue;
      Alignment pose;
      try {
        pose = align(a, b);
      } catch (const CalibError&) {
        continue;
      }
      std::size_t score = 0;
      std::vector<double> meds;
      for (const auto* s : scored) {
        const Fit f = fit_of(*s, pose, joints, o.inlier_threshold_m);
        score += f.agree;
        if (std::isfinite(f.median_m)) meds.push_back(f.median_m);
      }
      const double med = stats::upper_median(meds);
      if (score > best_score || (score == best_score && med < best_med)) {
        best = pose;
        best_score = score;
        best_med = med;
      }
    }
  }
  if (best_score == 0) throw CalibError("no frame gave a pose that any other frame agrees with");
  return best;
}

// Pair, solve, repeat until the pose settles; the last round's figures. The
// pose from a single frame is already robust (it won the frame-level RANSAC),
// so each round refits on the joint pairs within the threshold of the
// current pose (a minimal-sample RANSAC over single joints would be at the
// mercy of a few centimetres of noise on three points), weighted by their
// residuals (Cauchy).
SkeletonCalibResult solve(const std::vector<Candidate>& cs, Alignment pose, const std::vector<JointId>& joints,
                          const SkeletonCalibOptions& o) {
  SkeletonCalibResult r;
  for (int round = 0; round < 20; ++round) {
    const Pairs p = pair_up(cs, pose, joints, o);
    std::vector<Vector3d> a, b;
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < p.ref.size(); ++i) {
      if ((pose.apply(p.other[i]) - p.ref[i]).norm() <= o.inlier_threshold_m) {
        a.push_back(p.other[i]);
        b.push_back(p.ref[i]);
        idx.push_back(i);
      }
    }
    if (a.size() < 10) {
      throw CalibError("only " + std::to_string(a.size()) + " joint pairs agree with the best pose within " +
                       std::to_string(o.inlier_threshold_m) + " m (" + std::to_string(p.matched) + " frames matched, " +
                       std::to_string(p.mirrored) + " of them mirrored)");
    }
    // Robust weights (Cauchy, scale c): a joint the tracker placed far off
    // (hidden behind the body, still claimed) pulls less than a clean one.
    std::vector<double> w;
    const double c = o.robust_scale_m;
    for (std::size_t k = 0; k < a.size(); ++k) {
      const double d = (pose.apply(a[k]) - b[k]).norm();
      w.push_back(c > 0 && round > 0 ? 1.0 / (1.0 + (d / c) * (d / c)) : 1.0);
    }
    const Alignment fit = align(a, b, w);
    const double moved = (fit.t - pose.t).norm() + 0.01 * rotation_angle_deg(fit.R * pose.R.transpose());
    pose = fit;
    r.fit = fit;
    r.reference_frames = cs.size();
    r.matched = p.matched;
    r.mirrored = p.mirrored;
    r.pairs = p.ref.size();
    r.inliers = a.size();
    std::map<JointId, std::vector<double>> per;
    for (std::size_t k = 0; k < idx.size(); ++k) per[p.joint[idx[k]]].push_back(fit.residuals[k]);
    r.per_joint.clear();
    for (const auto j : joints) {
      auto& v = per[j];
      JointResidual jr{j, v.size(), stats::upper_median(v), 0.0};
      double ss = 0;
      for (double x : v) ss += x * x;
      jr.rms_m = v.empty() ? std::nan("") : std::sqrt(ss / static_cast<double>(v.size()));
      r.per_joint.push_back(jr);
    }
    if (moved < 1e-5) break;  // 0.01 mm (or 0.001 degree)
  }
  return r;
}

// Below this the person did not move about enough to tell a sensor's side (m, RMS).
constexpr double kMinSpreadM = 0.15;

// Where the person was (the reference's torsos) and which way is up (its
// spine), and how far the person moved about: the RMS distance of the torsos
// from their mean across the up axis.
struct Spread {
  Vector3d centre = Vector3d::Zero(), up = Vector3d::UnitY();
  double rms_m = 0;
  bool valid = false;
};

Spread spread_of(const std::vector<Candidate>& cs) {
  Spread sp;
  std::vector<Vector3d> torsos;
  Vector3d up = Vector3d::Zero();
  for (const auto& k : cs) {
    if (!tracked(*k.ref, JointId::Torso) || !tracked(*k.ref, JointId::Neck)) continue;
    torsos.push_back((*k.ref)[JointId::Torso].position);
    up += (*k.ref)[JointId::Neck].position - (*k.ref)[JointId::Torso].position;
  }
  if (torsos.empty() || up.norm() < 1e-9) return sp;
  sp.up = up.normalized();
  for (const auto& t : torsos) sp.centre += t;
  sp.centre /= static_cast<double>(torsos.size());
  double ss = 0;
  for (const auto& t : torsos) {
    const Vector3d d = t - sp.centre;
    ss += (d - d.dot(sp.up) * sp.up).squaredNorm();
  }
  sp.rms_m = std::sqrt(ss / static_cast<double>(torsos.size()));
  sp.valid = true;
  return sp;
}

// The pose turned by 180 degrees about the vertical through where the
// person was. For a person turning on the spot it explains the skeletons
// about as well as the pose itself, with every match's sides swapped the
// other way: a body turned round looks like its mirror image.
Alignment turned_about(const Spread& sp, const Alignment& pose) {
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(M_PI, sp.up).toRotationMatrix();
  Alignment a = pose;
  a.R = Q * pose.R;
  a.t = Q * (pose.t - sp.centre) + sp.centre;
  return a;
}

double median_residual(const std::vector<Candidate>& cs, const Alignment& pose, const std::vector<JointId>& joints,
                       const SkeletonCalibOptions& o) {
  const Pairs p = pair_up(cs, pose, joints, o);
  std::vector<double> d;
  for (std::size_t i = 0; i < p.ref.size(); ++i) d.push_back((pose.apply(p.other[i]) - p.ref[i]).norm());
  return d.size() < 10 ? std::numeric_limits<double>::infinity() : stats::upper_median(d);
}

}  // namespace

SkeletonCalibResult calibrate_from_skeletons(const std::vector<TimedSkeleton>& reference,
                                             const std::vector<TimedSkeleton>& other, const SkeletonCalibOptions& o) {
  const auto& joints = o.joints.empty() ? default_joints() : o.joints;
  if (reference.empty() || other.empty()) throw CalibError("need skeletons from both sensors");
  const auto tracks = tracks_of(other);
  auto cs = candidates(reference, tracks, 0, o.max_gap_ns);
  std::int64_t offset = 0;
  if (o.max_clock_offset_ns > 0) {
    // A first pose from the frames as they are (a person standing or walking
    // slowly fits it well enough), then in turn: the offset under which that
    // pose explains the data best, and the pose at that offset. The first
    // search spans the whole range in 20 ms steps, the later ones +-30 ms in 2 ms.
    if (cs.size() < 5) cs = candidates(reference, tracks, 0, 2 * o.max_clock_offset_ns);
    if (cs.size() < 5) {
      throw CalibError("the two sensors' skeletons never overlap in time (searched +-" +
                       std::to_string(o.max_clock_offset_ns / 1'000'000) + " ms)");
    }
    Alignment pose = propose(cs, joints, o);
    for (int round = 0; round < 4; ++round) {
      const std::int64_t lo = round == 0 ? -o.max_clock_offset_ns : std::max(-o.max_clock_offset_ns, offset - 30'000'000);
      const std::int64_t hi = round == 0 ? o.max_clock_offset_ns : std::min(o.max_clock_offset_ns, offset + 30'000'000);
      const std::int64_t step = round == 0 ? 20'000'000 : 2'000'000;
      double best = std::numeric_limits<double>::infinity();
      const std::int64_t before = offset;
      for (std::int64_t off = lo; off <= hi; off += step) {
        const double m = median_residual(candidates(reference, tracks, off, o.max_gap_ns), pose, joints, o);
        if (m < best) best = m, offset = off;
      }
      if (!std::isfinite(best)) throw CalibError("no clock offset within +-" + std::to_string(o.max_clock_offset_ns / 1'000'000) + " ms lets the skeletons agree");
      cs = candidates(reference, tracks, offset, o.max_gap_ns);
      pose = solve(cs, pose, joints, o).fit;
      if (round > 0 && offset == before) break;
    }
  }
  if (cs.size() < 5) {
    throw CalibError("only " + std::to_string(cs.size()) +
                     " reference frames have a skeleton of the other sensor within " +
                     std::to_string(o.max_gap_ns / 1'000'000) + " ms (do their times overlap? try a clock offset search)");
  }
  auto r = solve(cs, propose(cs, joints, o), joints, o);
  // The pose turned round about the person, solved too: the one more joint
  // pairs agree with wins. The skeletons cannot tell the two apart when the
  // person hardly moved about (turning on the spot: the rival then explains
  // the torsos too) or when as many pairs agree with both; then the one with
  // fewer views of the back is kept, as sensors watching a person mostly see
  // their front, and the result says it is ambiguous.
  const Spread sp = spread_of(cs);
  r.person_spread_m = sp.rms_m;
  if (sp.valid) {
    try {
      auto alt = solve(cs, turned_about(sp, r.fit), joints, o);
      r.turned_inliers = alt.inliers;
      alt.turned_inliers = r.inliers;
      alt.person_spread_m = sp.rms_m;
      const double lo = static_cast<double>(std::min(r.inliers, alt.inliers));
      const double hi = static_cast<double>(std::max(r.inliers, alt.inliers));
      const bool ambiguous = lo >= 0.95 * hi || sp.rms_m < kMinSpreadM;
      bool take_alt = alt.inliers > r.inliers;
      if (ambiguous && o.prior) {
        const Eigen::Matrix3d prior_R = o.prior->linear();
        take_alt = rotation_angle_deg(alt.fit.R * prior_R.transpose()) < rotation_angle_deg(r.fit.R * prior_R.transpose());
      } else if (ambiguous) {
        take_alt = alt.mirrored < r.mirrored;
      }
      if (take_alt) r = std::move(alt);
      r.ambiguous = ambiguous;
      r.resolved_by_prior = ambiguous && o.prior.has_value();
    } catch (const CalibError&) {
      // Nothing agrees with the turned pose: not a rival.
      r.ambiguous = sp.rms_m < kMinSpreadM;
    }
  }
  r.clock_offset_ns = offset;
  return r;
}

Correspondences correspondences(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                const Eigen::Isometry3d& reference_from_other, const SkeletonCalibOptions& o) {
  const auto& joints = o.joints.empty() ? default_joints() : o.joints;
  Alignment pose;
  pose.R = reference_from_other.linear();
  pose.t = reference_from_other.translation();
  const Pairs p = pair_up(candidates(reference, tracks_of(other), 0, o.max_gap_ns), pose, joints, o);
  Correspondences c;
  c.matched = p.matched;
  c.mirrored = p.mirrored;
  for (std::size_t i = 0; i < p.ref.size(); ++i) {
    if ((pose.apply(p.other[i]) - p.ref[i]).norm() > o.inlier_threshold_m) continue;
    c.reference.push_back(p.ref[i]);
    c.other.push_back(p.other[i]);
    c.mirrored_pair.push_back(p.swapped[i]);
  }
  return c;
}

std::vector<double> joint_distances(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                    const Eigen::Isometry3d& reference_from_other, std::int64_t clock_offset_ns,
                                    const std::vector<JointId>& joints_in, double max_match_m, std::int64_t max_gap_ns) {
  const auto& joints = joints_in.empty() ? default_joints() : joints_in;
  std::vector<double> out;
  for (const auto& c : candidates(reference, tracks_of(other), clock_offset_ns, max_gap_ns)) {
    double best = std::numeric_limits<double>::infinity();
    std::vector<double> best_d;
    for (const auto& o : c.others) {
      for (const bool swapped : {false, true}) {  // as labelled, or a view of the back with its sides swapped
        std::vector<double> d;
        for (const auto j : joints) {
          const JointId oj = swapped ? skeleton::mirror(j) : j;
          if (tracked(*c.ref, j) && tracked(o, oj)) d.push_back((reference_from_other * o[oj].position - (*c.ref)[j].position).norm());
        }
        if (d.empty()) continue;
        const double m = stats::upper_median(d);
        if (m < best) best = m, best_d = std::move(d);
      }
    }
    if (best <= max_match_m) out.insert(out.end(), best_d.begin(), best_d.end());
  }
  return out;
}

namespace {

// One local search (see lowest_median_pose) from `start`.
LowestMedian lowest_median_near(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                const Eigen::Isometry3d& start, std::int64_t clock_offset_ns,
                                const std::vector<JointId>& joints, double max_match_m) {
  using V6 = Eigen::Matrix<double, 6, 1>;
  const auto pose_of = [&](const V6& x) {
    Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
    const Vector3d w = x.head<3>();
    if (w.norm() > 0) d.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    d.translation() = x.tail<3>();
    return Eigen::Isometry3d(d * start);
  };
  const auto cost = [&](const V6& x) {
    const double m = stats::upper_median(joint_distances(reference, other, pose_of(x), clock_offset_ns, joints, max_match_m));
    return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
  };
  LowestMedian out;
  V6 best = V6::Zero();
  double best_f = out.start_median_m = cost(best);
  out.reference_from_other = start;
  out.median_m = best_f;
  if (!std::isfinite(best_f)) return out;  // nothing matched at the start: nothing to search on
  // Steps: 2 degrees and 5 cm, then a third and a ninth of that.
  for (double scale : {1.0, 1.0 / 3, 1.0 / 9}) {
    std::array<V6, 7> x;
    std::array<double, 7> f;
    for (auto& v : x) v = best;
    for (int i = 0; i < 6; ++i) x[static_cast<std::size_t>(i + 1)][i] += scale * (i < 3 ? 0.035 : 0.05);
    for (std::size_t i = 0; i < 7; ++i) f[i] = cost(x[i]);
    for (int it = 0; it < 400; ++it) {
      std::array<std::size_t, 7> ord{0, 1, 2, 3, 4, 5, 6};
      std::sort(ord.begin(), ord.end(), [&](std::size_t a, std::size_t b) { return f[a] < f[b]; });
      std::array<V6, 7> xs;
      std::array<double, 7> fs;
      for (std::size_t i = 0; i < 7; ++i) xs[i] = x[ord[i]], fs[i] = f[ord[i]];
      x = xs, f = fs;
      if (f[6] - f[0] < 1e-6) break;  // a thousandth of a millimetre
      V6 c = V6::Zero();
      for (std::size_t i = 0; i < 6; ++i) c += x[i];
      c /= 6;
      const V6 xr = c + (c - x[6]);
      const double fr = cost(xr);
      if (fr < f[0]) {
        const V6 xe = c + 2 * (c - x[6]);
        const double fe = cost(xe);
        if (fe < fr) x[6] = xe, f[6] = fe;
        else x[6] = xr, f[6] = fr;
      } else if (fr < f[5]) {
        x[6] = xr, f[6] = fr;
      } else {
        const V6 xc = c + 0.5 * (x[6] - c);
        const double fc = cost(xc);
        if (fc < f[6]) {
          x[6] = xc, f[6] = fc;
        } else {
          for (std::size_t i = 1; i < 7; ++i) x[i] = x[0] + 0.5 * (x[i] - x[0]), f[i] = cost(x[i]);
        }
      }
    }
    const auto k = static_cast<std::size_t>(std::min_element(f.begin(), f.end()) - f.begin());
    if (f[k] < best_f) best_f = f[k], best = x[k];
  }
  out.reference_from_other = pose_of(best);
  out.median_m = best_f;
  return out;
}

}  // namespace

LowestMedian lowest_median_pose(const std::vector<TimedSkeleton>& reference, const std::vector<TimedSkeleton>& other,
                                const Eigen::Isometry3d& start, std::int64_t clock_offset_ns,
                                const std::vector<JointId>& joints, double max_match_m, int starts) {
  if (starts < 1) throw CalibError("lowest_median_pose: starts must be at least 1");
  auto out = lowest_median_near(reference, other, start, clock_offset_ns, joints, max_match_m);
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 1; k < starts; ++k) {
    Vector3d axis(u(rng), u(rng), u(rng));
    if (axis.norm() < 1e-6) axis = Vector3d::UnitY();
    const double angle = 10.0 * M_PI / 180.0 * std::abs(u(rng));
    Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
    d.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
    d.translation() = 0.3 * Vector3d(u(rng), u(rng), u(rng));
    const auto r = lowest_median_near(reference, other, d * start, clock_offset_ns, joints, max_match_m);
    if (r.median_m < out.median_m) out.reference_from_other = r.reference_from_other, out.median_m = r.median_m;
  }
  out.starts = starts;
  return out;
}

}  // namespace skelgraph::calib
