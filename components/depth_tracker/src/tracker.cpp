#include "skelgraph/depth_tracker/tracker.hpp"

#include <algorithm>
#include <utility>
#include <array>
#include <cmath>
#include <initializer_list>
#include <map>
#include <memory>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "skelgraph/depth/cloud.hpp"

namespace skelgraph::depth_tracker {

using skeleton::JointId;
using Eigen::Vector3d;
constexpr std::size_t kJ = skeleton::kJointCount;
constexpr int kN = static_cast<int>(kJ) * 3;
using Mat = Eigen::Matrix<double, kN, kN>;
using Vec = Eigen::Matrix<double, kN, 1>;
using Pose = std::array<Vector3d, kJ>;

namespace {

std::size_t idx(JointId j) { return static_cast<std::size_t>(j); }

// A capsule end: a joint, or the middle of two (the pelvis).
struct End {
  std::size_t a, b;  // joints; a == b for a joint itself
  Vector3d at(const Pose& p) const { return a == b ? p[a] : 0.5 * (p[a] + p[b]); }
};
struct Segment {
  End from, to;
  double radius;  // fraction of body height
};

End J(JointId j) { return {idx(j), idx(j)}; }
End Mid(JointId a, JointId b) { return {idx(a), idx(b)}; }

// The body's volume (radii as fractions of height: a 1.75 m person's head is ~0.10 m in radius).
const std::vector<Segment>& segments() {
  using J_ = JointId;
  static const std::vector<Segment> s = {
      {J(J_::Head), J(J_::Head), 0.056},
      {J(J_::Neck), J(J_::Head), 0.030},
      {J(J_::LeftShoulder), J(J_::RightShoulder), 0.034},
      {J(J_::LeftShoulder), J(J_::LeftHip), 0.048},
      {J(J_::RightShoulder), J(J_::RightHip), 0.048},
      {J(J_::Neck), J(J_::Torso), 0.057},
      {J(J_::Torso), Mid(J_::LeftHip, J_::RightHip), 0.062},
      {J(J_::LeftHip), J(J_::RightHip), 0.051},
      {J(J_::LeftShoulder), J(J_::LeftElbow), 0.026},
      {J(J_::RightShoulder), J(J_::RightElbow), 0.026},
      {J(J_::LeftElbow), J(J_::LeftHand), 0.022},
      {J(J_::RightElbow), J(J_::RightHand), 0.022},
      {J(J_::LeftHand), J(J_::LeftHand), 0.028},
      {J(J_::RightHand), J(J_::RightHand), 0.028},
      {J(J_::LeftHip), J(J_::LeftKnee), 0.043},
      {J(J_::RightHip), J(J_::RightKnee), 0.043},
      {J(J_::LeftKnee), J(J_::LeftFoot), 0.029},
      {J(J_::RightKnee), J(J_::RightFoot), 0.029},
      {J(J_::LeftFoot), J(J_::LeftFoot), 0.029},
      {J(J_::RightFoot), J(J_::RightFoot), 0.029},
  };
  return s;
}

// Pairs whose distance is kept: the bones, and enough links to keep the trunk rigid.
const std::vector<std::pair<JointId, JointId>>& links() {
  using J_ = JointId;
  static const std::vector<std::pair<JointId, JointId>> l = {
      {J_::Neck, J_::Head},          {J_::Torso, J_::Head},          {J_::Neck, J_::Torso},          {J_::Neck, J_::LeftShoulder},
      {J_::Neck, J_::RightShoulder}, {J_::LeftShoulder, J_::RightShoulder}, {J_::Torso, J_::LeftShoulder}, {J_::Torso, J_::RightShoulder},
      {J_::Torso, J_::LeftHip},      {J_::Torso, J_::RightHip},      {J_::LeftHip, J_::RightHip},    {J_::LeftShoulder, J_::LeftHip},
      {J_::RightShoulder, J_::RightHip}, {J_::LeftShoulder, J_::RightHip}, {J_::RightShoulder, J_::LeftHip}, {J_::Neck, J_::LeftHip},
      {J_::Neck, J_::RightHip},      {J_::LeftShoulder, J_::LeftElbow}, {J_::LeftElbow, J_::LeftHand}, {J_::RightShoulder, J_::RightElbow},
      {J_::RightElbow, J_::RightHand}, {J_::LeftHip, J_::LeftKnee},  {J_::LeftKnee, J_::LeftFoot},   {J_::RightHip, J_::RightKnee},
      {J_::RightKnee, J_::RightFoot},
  };
  return l;
}

// A standing person `h` tall, pelvis over `centre` (x, z), facing `fwd`
// (horizontal), arms hanging slightly away from the body. Proportions of
// height after Drillis & Contini (Winter, "Biomechanics and Motor Control
// of Human Movement").
Pose standing(double h, const Vector3d& centre, const Vector3d& fwd) {
  const Vector3d up = Vector3d::UnitY();
  const Vector3d left = up.cross(fwd).normalized();
  Pose p;
  const Vector3d pelvis(centre.x(), 0.530 * h, centre.z());
  const Vector3d neck = pelvis + 0.288 * h * up;
  p[idx(JointId::Neck)] = neck;
  p[idx(JointId::Torso)] = 0.5 * (pelvis + neck);
  p[idx(JointId::Head)] = neck + 0.118 * h * up;
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? 1.0 : -1.0;
    const Vector3d out = sign * left;
    const Vector3d shoulder = neck + 0.1295 * h * out;
    const Vector3d arm_dir = (-up * std::cos(0.25) + out * std::sin(0.25)).normalized();
    const Vector3d elbow = shoulder + 0.186 * h * arm_dir;
    const Vector3d hand = elbow + 0.195 * h * arm_dir;
    const Vector3d hip = pelvis + 0.055 * h * out;
    const Vector3d knee = hip - 0.245 * h * up;
    const Vector3d foot = knee - 0.246 * h * up;
    const bool l = side == 0;
    p[idx(l ? JointId::LeftShoulder : JointId::RightShoulder)] = shoulder;
    p[idx(l ? JointId::LeftElbow : JointId::RightElbow)] = elbow;
    p[idx(l ? JointId::LeftHand : JointId::RightHand)] = hand;
    p[idx(l ? JointId::LeftHip : JointId::RightHip)] = hip;
    p[idx(l ? JointId::LeftKnee : JointId::RightKnee)] = knee;
    p[idx(l ? JointId::LeftFoot : JointId::RightFoot)] = foot;
  }
  return p;
}

Vector3d pelvis_of(const Pose& p) { return 0.5 * (p[idx(JointId::LeftHip)] + p[idx(JointId::RightHip)]); }

// The way the hips and trunk face (the body's own up, crossed with its left).
Vector3d body_forward(const Pose& p) {
  const Vector3d up = p[idx(JointId::Neck)] - pelvis_of(p);
  const Vector3d left = p[idx(JointId::LeftHip)] - p[idx(JointId::RightHip)];
  const Vector3d fwd = left.cross(up);
  return fwd.norm() > 1e-9 ? Vector3d(fwd.normalized()) : Vector3d::Zero();
}

// Arms and legs: root, middle (the hinge) and end joints.
struct Limb {
  std::array<std::size_t, 3> joints;
  bool knee;
};
const std::array<Limb, 4>& limbs() {
  using J_ = JointId;
  static const std::array<Limb, 4> l = {{
      {{idx(J_::LeftShoulder), idx(J_::LeftElbow), idx(J_::LeftHand)}, false},
      {{idx(J_::RightShoulder), idx(J_::RightElbow), idx(J_::RightHand)}, false},
      {{idx(J_::LeftHip), idx(J_::LeftKnee), idx(J_::LeftFoot)}, true},
      {{idx(J_::RightHip), idx(J_::RightKnee), idx(J_::RightFoot)}, true},
  }};
  return l;
}

// Adds w r^2 to the Gauss-Newton system, r depending on up to three joints
// with gradients g (dr/dx_joint): A += w J^T J, b -= w J^T r.
void add_residual(Mat& A, Vec& b, std::initializer_list<std::pair<std::size_t, Vector3d>> grad, double r, double w) {
  for (const auto& [jk, gk] : grad) {
    for (const auto& [jl, gl] : grad) {
      A.block<3, 3>(3 * static_cast<int>(jk), 3 * static_cast<int>(jl)) += w * gk * gl.transpose();
    }
    b.segment<3>(3 * static_cast<int>(jk)) -= w * gk * r;
  }
}

struct Person {
  std::uint32_t id = 0;
  double height = 1.75;
  Pose pose{};
  std::vector<double> lengths;  // per link
  std::int64_t last_seen_ns = 0;
  std::array<double, kJ> support{};
};

// Closest point on segment a-b to p, as the fraction along it.
double closest_fraction(const Vector3d& a, const Vector3d& b, const Vector3d& p) {
  const Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 < 1e-12) return 0.0;
  return std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
}

}  // namespace

LimitViolation check_joint_limits(const skeleton::Skeleton& s, const JointLimits& limits) {
  Pose x;
  for (std::size_t k = 0; k < kJ; ++k) x[k] = s.joints[k].position;
  const Vector3d fwd = body_forward(x);
  LimitViolation v;
  for (const auto& limb : limbs()) {
    const auto [a, m, e] = limb.joints;
    const Vector3d u = x[a] - x[m], w = x[e] - x[m];
    if (u.norm() < 1e-9 || w.norm() < 1e-9) continue;
    const double angle = std::acos(std::clamp(u.normalized().dot(w.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
    double& worst = limb.knee ? v.knee_deg : v.elbow_deg;
    worst = std::max(worst, (limb.knee ? limits.min_knee_deg : limits.min_elbow_deg) - angle);
    if (limb.knee) v.knee_back_m = std::max(v.knee_back_m, -(x[m] - 0.5 * (x[a] + x[e])).dot(fwd) - limits.knee_back_m);
  }
  return v;
}

struct DepthTracker::Impl {
  TrackerOptions opt;
  Eigen::Isometry3d world_from_sensor = Eigen::Isometry3d::Identity();
  std::vector<Person> people;
  std::uint32_t next_id = 1;
  std::vector<std::uint32_t> dropped;  // forgotten since take_dropped()
  TrackerStats stats;

  struct Fit {
    double mean_abs = 0.0;  // mean |distance to the surface| of the inlying points
    double inliers = 0.0;   // their share of the points
    double score() const { return mean_abs + 0.1 * (1.0 - inliers); }
  };
  // The images of the frame being tracked, for the free-space term of the fit.
  struct View {
    const depth::DepthImage* image;
    Eigen::Isometry3d sensor_from_world;
  };
  std::vector<View> views;
  // Fits `person` to the points.
  Fit fit(Person& person, const depth::Points& points, int iterations) const;
  Fit start(Person& person, const PersonPoints& found, const Eigen::Vector3d& viewpoint, double height) const;
  std::vector<skeleton::Skeleton> step(std::vector<PersonPoints> found, std::int64_t stamp_ns,
                                       const std::vector<Vector3d>& viewpoints);
};

DepthTracker::DepthTracker(TrackerOptions options) : impl_(std::make_unique<Impl>()) {
  if (!(options.voxel_m > 0) || options.iterations < 1 || options.init_iterations < 1 || !(options.outlier_m > 0) ||
      !(options.bone_weight >= 0) || !(options.smooth_weight >= 0) || !(options.limit_weight >= 0) || !(options.max_height_m > options.min_height_m)) {
    throw std::invalid_argument("depth tracker: bad options");
  }
  impl_->opt = options;
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.translation() = Vector3d(0.0, 1.2, 0.0);
  impl_->world_from_sensor = level;
}
DepthTracker::~DepthTracker() = default;
DepthTracker::DepthTracker(DepthTracker&&) noexcept = default;
DepthTracker& DepthTracker::operator=(DepthTracker&&) noexcept = default;

void DepthTracker::set_pose(const Eigen::Isometry3d& world_from_sensor) { impl_->world_from_sensor = world_from_sensor; }
const Eigen::Isometry3d& DepthTracker::pose() const { return impl_->world_from_sensor; }
std::vector<std::uint32_t> DepthTracker::take_dropped() { return std::exchange(impl_->dropped, {}); }

const TrackerStats& DepthTracker::stats() const { return impl_->stats; }
const TrackerOptions& DepthTracker::options() const { return impl_->opt; }

DepthTracker::Impl::Fit DepthTracker::Impl::fit(Person& person, const depth::Points& points, int iterations) const {
  const auto& segs = segments();
  const auto& lks = links();
  const Pose previous = person.pose;
  Fit result;
  std::vector<double> radius(segs.size());
  for (std::size_t s = 0; s < segs.size(); ++s) radius[s] = segs[s].radius * person.height;
  // Per joint, the thickest capsule it ends (its footprint in the image).
  std::array<double, kJ> joint_radius{};
  for (std::size_t s = 0; s < segs.size(); ++s)
    for (const auto j : {segs[s].from.a, segs[s].from.b, segs[s].to.a, segs[s].to.b})
      joint_radius[j] = std::max(joint_radius[j], radius[s]);
  std::vector<int> inliers(segs.size());
  for (int it = 0; it < iterations; ++it) {
    Mat A = Mat::Zero();
    Vec b = Vec::Zero();
    std::fill(inliers.begin(), inliers.end(), 0);
    double abs_sum = 0.0;
    int used = 0;
    const Pose& x = person.pose;
    std::vector<Vector3d> ends_a(segs.size()), ends_b(segs.size());
    for (std::size_t s = 0; s < segs.size(); ++s) {
      ends_a[s] = segs[s].from.at(x);
      ends_b[s] = segs[s].to.at(x);
    }
    for (const auto& pf : points) {
      const Vector3d p = pf.cast<double>();
      // The capsule whose surface is nearest (signed: inside counts as nearer).
      double best = 1e9, best_s_frac = 0.0;
      std::size_t best_seg = 0;
      for (std::size_t s = 0; s < segs.size(); ++s) {
        const double f = closest_fraction(ends_a[s], ends_b[s], p);
        const double d = (p - (ends_a[s] + f * (ends_b[s] - ends_a[s]))).norm() - radius[s];
        if (d < best) {
          best = d;
          best_seg = s;
          best_s_frac = f;
        }
      }
      if (std::abs(best) > opt.outlier_m) continue;
      const Vector3d q = ends_a[best_seg] + best_s_frac * (ends_b[best_seg] - ends_a[best_seg]);
      const Vector3d diff = p - q;
      const double dist = diff.norm();
      if (dist < 1e-9) continue;
      const Vector3d n = diff / dist;
      const double e = dist - radius[best_seg];
      const double w = std::abs(e) < 0.03 ? 1.0 : 0.03 / std::abs(e);  // Huber
      ++inliers[best_seg];
      abs_sum += std::abs(e);
      ++used;
      // q = (1-f) * from + f * to; from/to are joints or the mean of two.
      std::array<std::pair<std::size_t, double>, 4> coef = {{{segs[best_seg].from.a, 0.5 * (1 - best_s_frac)},
                                                             {segs[best_seg].from.b, 0.5 * (1 - best_s_frac)},
                                                             {segs[best_seg].to.a, 0.5 * best_s_frac},
                                                             {segs[best_seg].to.b, 0.5 * best_s_frac}}};
      // d e / d joint_k = -c_k n^T
      for (const auto& [jk, ck] : coef) {
        if (ck == 0.0) continue;
        for (const auto& [jl, cl] : coef) {
          if (cl == 0.0) continue;
          A.block<3, 3>(3 * static_cast<int>(jk), 3 * static_cast<int>(jl)) += w * ck * cl * (n * n.transpose());
        }
        b.segment<3>(3 * static_cast<int>(jk)) += w * ck * n * e;  // -J^T e with J = -c n^T
      }
    }
    result.mean_abs = used > 0 ? abs_sum / used : 0.0;
    result.inliers = points.empty() ? 0.0 : static_cast<double>(used) / static_cast<double>(points.size());
    // Bone lengths and the trunk's shape.
    for (std::size_t l = 0; l < lks.size(); ++l) {
      const auto i = idx(lks[l].first), j = idx(lks[l].second);
      const Vector3d d = x[i] - x[j];
      const double len = d.norm();
      if (len < 1e-9) continue;
      const Vector3d u = d / len;
      add_residual(A, b, {{i, u}, {j, -u}}, len - person.lengths[l], opt.bone_weight);
    }
    // Joint limits, where broken.
    if (opt.limit_weight > 0) {
      const Vector3d fwd = body_forward(x);
      for (const auto& limb : limbs()) {
        const auto [a, m, e] = limb.joints;
        const double l1 = (x[a] - x[m]).norm(), l2 = (x[m] - x[e]).norm();
        const double fold = (limb.knee ? opt.limits.min_knee_deg : opt.limits.min_elbow_deg) * M_PI / 180.0;
        const double reach_min = std::sqrt(std::max(0.0, l1 * l1 + l2 * l2 - 2 * l1 * l2 * std::cos(fold)));
        const Vector3d ae = x[e] - x[a];
        const double reach = ae.norm();
        if (reach < reach_min && reach > 1e-9) {
          const Vector3d u = ae / reach;
          add_residual(A, b, {{e, u}, {a, -u}}, reach - reach_min, opt.limit_weight);
        }
        if (limb.knee) {
          const double ahead = (x[m] - 0.5 * (x[a] + x[e])).dot(fwd);
          if (ahead < -opt.limits.knee_back_m) {
            add_residual(A, b, {{m, fwd}, {a, -0.5 * fwd}, {e, -0.5 * fwd}}, ahead + opt.limits.knee_back_m,
                         opt.limit_weight);
          }
        }
      }
    }
    // Free space: a limb the sensor would have seen is in the image (an
    // elbow held out in front of the trunk would be). A joint whose pixel
    // shows a surface more than free_space_m behind it is in the air, unless
    // its limb's own surface is beside it: a reading, within the footprint
    // (a disc of the limb's radius about the pixel), at about the depth of
    // the limb's front. (Beside a thin limb the pixel shows the room behind
    // it.) A pixel nearer than the limb's front hides the joint; pixels
    // without a reading say nothing (holes, removed background).
    if (opt.free_space_weight > 0) {
      for (const auto& view : views) {
        const auto& img = *view.image;
        const Eigen::RowVector3d gz = view.sensor_from_world.linear().row(2);
        const auto reading = [&](double u, double v) -> double {
          const long iu = std::lround(u), iv = std::lround(v);
          if (iu < 0 || iv < 0 || iu >= img.width() || iv >= img.height()) return 0.0;
          return img.at(static_cast<int>(iu), static_cast<int>(iv)) * 1e-3;
        };
        for (std::size_t k = 0; k < kJ; ++k) {
          const Vector3d ps = view.sensor_from_world * x[k];
          if (ps.z() <= 0.05) continue;
          const auto px = depth::project(img.intrinsics, ps);
          const double seen = reading(px.x(), px.y());
          const double front = ps.z() - joint_radius[k] - opt.free_space_m;  // nearer than this: something in front of the limb
          if (seen <= 0 || seen < front || seen <= ps.z() + opt.free_space_m) continue;
          const double r_px = img.intrinsics.fx * joint_radius[k] / ps.z();
          bool limb_beside = false;
          for (int i = -2; i <= 2 && !limb_beside; ++i) {
            for (int j = -2; j <= 2 && !limb_beside; ++j) {
              if (i * i + j * j > 4) continue;
              const double r = reading(px.x() + r_px * i / 2.0, px.y() + r_px * j / 2.0);
              limb_beside = r > 0 && r >= front && r <= ps.z() + opt.free_space_m;
            }
          }
          if (limb_beside) continue;
          const double e = ps.z() - (seen - opt.free_space_m);
          if (e > -opt.free_space_depth_m) add_residual(A, b, {{k, gz.transpose()}}, e, opt.free_space_weight);
        }
      }
    }
    // Towards the previous frame's pose, and a little damping.
    for (std::size_t k = 0; k < kJ; ++k) {
      A.block<3, 3>(3 * static_cast<int>(k), 3 * static_cast<int>(k)) +=
          (opt.smooth_weight + 0.5) * Eigen::Matrix3d::Identity();
      b.segment<3>(3 * static_cast<int>(k)) -= opt.smooth_weight * (x[k] - previous[k]);
    }
    const Vec step = A.ldlt().solve(b);
    if (!step.allFinite()) break;
    for (std::size_t k = 0; k < kJ; ++k) {
      Vector3d s = step.segment<3>(3 * static_cast<int>(k));
      if (s.norm() > 0.1) s *= 0.1 / s.norm();  // a step never jumps more than 10 cm
      person.pose[k] += s;
    }
  }
  // Support per joint: inlying points on the segments that move it.
  person.support.fill(0.0);
  for (std::size_t s = 0; s < segs.size(); ++s) {
    for (const auto j : {segs[s].from.a, segs[s].from.b, segs[s].to.a, segs[s].to.b}) {
      person.support[j] += inliers[s];
    }
  }
  return result;
}

std::vector<PersonPoints> find_people(const depth::DepthImage& image, const Eigen::Isometry3d& world_from_sensor,
                                      const TrackerOptions& opt) {
  depth::check(image);
  const int w = image.width(), h = image.height();
  const Eigen::Matrix3d R = world_from_sensor.linear();
  const Vector3d t = world_from_sensor.translation();

  // Everything with a reading above the floor.
  std::vector<std::uint8_t> mask(image.mm.size(), 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const auto i = static_cast<std::size_t>(v) * w + u;
      if (image.mm[i] == 0) continue;
      const double y = R.row(1).dot(depth::unproject(image.intrinsics, u, v, image.mm[i] * 1e-3)) + t.y();
      mask[i] = y > opt.floor_margin_m;
    }
  }
  const auto seg = depth::segment(image, mask, opt.max_step_m, static_cast<std::size_t>(w) * h / 400);

  // Regions as thinned world points; parts of one body that depth steps split
  // (an arm in front of the trunk seen from the side) are joined again by
  // where they stand; then only person-shaped groups are kept.
  using Candidate = PersonPoints;
  std::vector<Candidate> parts;
  for (const auto& r : seg.regions) {
    std::vector<std::uint8_t> rm(image.mm.size(), 0);
    for (std::size_t i = 0; i < rm.size(); ++i) rm[i] = seg.labels[i] == r.label;
    auto pts = depth::voxel_downsample(depth::transformed(depth::to_points(image, rm), world_from_sensor), opt.voxel_m);
    if (pts.size() < 5) continue;
    Vector3d sum = Vector3d::Zero();
    for (const auto& p : pts) sum += p.cast<double>();
    const Vector3d centre = sum / static_cast<double>(pts.size());
    bool cut = false;  // on the last two rows of the image
    for (int v = std::max(0, h - 2); v < h && !cut; ++v)
      for (int u = 0; u < w && !cut; ++u) cut = rm[static_cast<std::size_t>(v) * w + u] != 0;
    parts.push_back({std::move(pts), centre, 0.0, cut});
  }
  // Largest first (segment() sorts regions by size): each part joins the first group standing within 0.45 m;
  // in a close view cut off below, a part touching a group (points within 10 cm: an arm held out in front
  // of the trunk, split from it by the depth step) joins it too, and so does a hand held out (below).
  const auto touching = [](const Candidate& a, const Candidate& b) {
    for (const auto& p : a.points)
      for (const auto& q : b.points)
        if ((p - q).squaredNorm() < 0.01f) return true;
    return false;
  };
  // A hand held out towards the sensor is its own region (the forearm behind
  // it is hidden, the depth steps at its edge): a part no bigger than a hand
  // or forearm, nearer the sensor than a group and within reach of its points,
  // joins that group. (On ../shared/data/skeltrack-depth such hands are
  // 0.35-0.5 m in front of the trunk and 9-35 cm from its nearest point.)
  const Vector3d eye = t;
  const auto reach_part = [&](const Candidate& part, const Candidate& g) {
    Eigen::AlignedBox3d box;
    for (const auto& p : part.points) box.extend(p.cast<double>());
    if (box.sizes().maxCoeff() > opt.max_hand_part_m) return false;
    if ((part.centre - eye).norm() >= (g.centre - eye).norm()) return false;
    const float r2 = static_cast<float>(opt.hand_reach_m * opt.hand_reach_m);
    for (const auto& p : part.points)
      for (const auto& q : g.points)
        if ((p - q).squaredNorm() < r2) return true;
    return false;
  };
  std::vector<Candidate> groups;
  const auto join = [](Candidate& home, Candidate& part) {
    const double n0 = static_cast<double>(home.points.size()), n1 = static_cast<double>(part.points.size());
    home.centre = (home.centre * n0 + part.centre * n1) / (n0 + n1);
    home.cut_at_bottom = home.cut_at_bottom || part.cut_at_bottom;
    home.points.insert(home.points.end(), part.points.begin(), part.points.end());
  };
  for (auto& part : parts) {
    Candidate* home = nullptr;
    for (auto& g : groups) {
      if (std::hypot(g.centre.x() - part.centre.x(), g.centre.z() - part.centre.z()) < 0.45 ||
          (part.cut_at_bottom && g.cut_at_bottom && touching(part, g)) || reach_part(part, g)) {
        home = &g;
        break;
      }
    }
    if (home == nullptr) {
      groups.push_back(std::move(part));
      continue;
    }
    join(*home, part);
  }
  std::vector<Candidate> found;
  for (auto& g : groups) {
    if (g.points.size() < opt.min_points) continue;
    Eigen::AlignedBox3d box;
    std::vector<double> ys;
    for (const auto& p : g.points) {
      box.extend(p.cast<double>());
      ys.push_back(p.y());
    }
    const auto k = static_cast<long>(ys.size() * 98 / 100);
    std::nth_element(ys.begin(), ys.begin() + k, ys.end());
    g.top = ys[static_cast<std::size_t>(k)];
    // The head's top: the top of the points over the group's middle (its
    // median place across), so that hands raised beside the head do not make
    // the person taller.
    std::vector<double> xs, zs;
    for (const auto& p : g.points) {
      xs.push_back(p.x());
      zs.push_back(p.z());
    }
    const auto mid = xs.size() / 2;
    std::nth_element(xs.begin(), xs.begin() + static_cast<long>(mid), xs.end());
    std::nth_element(zs.begin(), zs.begin() + static_cast<long>(mid), zs.end());
    std::vector<double> middle;
    for (const auto& p : g.points) {
      if (std::hypot(p.x() - xs[mid], p.z() - zs[mid]) < 0.25) middle.push_back(p.y());
    }
    g.crown = g.top;
    if (middle.size() >= 10) {
      const auto m = static_cast<long>(middle.size() * 98 / 100);
      std::nth_element(middle.begin(), middle.begin() + m, middle.end());
      g.crown = std::min(g.top, middle[static_cast<std::size_t>(m)]);
    }
    const double width = std::hypot(box.sizes().x(), box.sizes().z());
    if (g.top < opt.min_height_m || g.top > opt.max_height_m || width > opt.max_width_m) continue;
    // An arm, a box: not a whole person; unless the image cut it off below (a close, upper-body view).
    if (box.sizes().y() < (g.cut_at_bottom ? opt.min_upper_extent_m : opt.min_extent_m)) continue;
    if ((g.centre - t).norm() > opt.max_distance_m) continue;
    // Flat: a piece of wall between shadows, not a body.
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : g.points) {
      const Vector3d q = p.cast<double>() - g.centre;
      cov += q * q.transpose();
    }
    cov /= static_cast<double>(g.points.size());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    if (std::sqrt(std::max(eig.eigenvalues()(0), 0.0)) < opt.min_thickness_m) continue;
    found.push_back(std::move(g));
  }
  return found;
}

// A new person from a person-shaped group of points: a standing template
// `height` tall, its head's top at the group's crown, turned every 45 degrees,
// then each arm tried in many poses; the best explanation of the points.
DepthTracker::Impl::Fit DepthTracker::Impl::start(Person& p, const PersonPoints& found, const Vector3d& viewpoint,
                                                  double height) const {
  const double crown = found.crown;
  Vector3d to_sensor = viewpoint - found.centre;
  to_sensor.y() = 0.0;
  if (to_sensor.norm() < 1e-6) to_sensor = Vector3d::UnitZ();
  to_sensor.normalize();
  // The points are the front of the body: its middle is about a hand's breadth behind them.
  const Vector3d centre = found.centre - 0.1 * to_sensor;
  // A standing template `h` tall whose head's top is at the crown (on the floor when h is the crown).
  const auto template_of = [&](double h, const Vector3d& fwd) {
    Person trial = p;
    trial.height = h;
    trial.pose = standing(h, centre, fwd);
    for (auto& j : trial.pose) j.y() += crown - h;
    trial.lengths.clear();
    for (const auto& [ja, jb] : links()) trial.lengths.push_back((trial.pose[idx(ja)] - trial.pose[idx(jb)]).norm());
    return trial;
  };
  // Which way they face is not known: fit a standing template turned every
  // 45 degrees and keep the best (facing the sensor wins ties).
  Fit best_fit;
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4.0;
    Person trial = template_of(height, Eigen::AngleAxisd(a, Vector3d::UnitY()) * to_sensor);
    const auto f = fit(trial, found.points, opt.init_iterations);
    if (k == 0 || f.score() < best_fit.score() - 1e-3) {
      best_fit = f;
      p = trial;
    }
  }
  // Arms need not hang at the start: try each arm's upper arm and forearm
  // down, forward, out, up and in between (straight or bent at the elbow:
  // a fist raised from an arm held out, a hand held forward from an arm
  // hanging), rank the tries by a short fit and refine the best few; keep
  // what explains the points best.
  const Vector3d up = Vector3d::UnitY();
  const Vector3d left_dir = (p.pose[idx(JointId::LeftShoulder)] - p.pose[idx(JointId::RightShoulder)]).normalized();
  const Vector3d fwd = left_dir.cross(up).normalized();
  for (const auto& [sh, el, ha, out_sign] : {std::tuple{JointId::LeftShoulder, JointId::LeftElbow, JointId::LeftHand, 1.0},
                                             std::tuple{JointId::RightShoulder, JointId::RightElbow, JointId::RightHand, -1.0}}) {
    const Vector3d side = out_sign * left_dir;
    const std::array<Vector3d, 9> dirs = {-up, fwd, side, up, Vector3d((fwd - up).normalized()), Vector3d((fwd + up).normalized()),
                                          Vector3d((side - up).normalized()), Vector3d((side + up).normalized()),
                                          Vector3d((side + fwd).normalized())};
    const double upper = (p.pose[idx(el)] - p.pose[idx(sh)]).norm();
    const double fore = (p.pose[idx(ha)] - p.pose[idx(el)]).norm();
    const auto arm_at = [&](const Vector3d& du, const Vector3d& df) {
      Person trial = p;
      trial.pose[idx(el)] = trial.pose[idx(sh)] + upper * du;
      trial.pose[idx(ha)] = trial.pose[idx(el)] + fore * df;
      return trial;
    };
    struct Try {
      double score;
      std::size_t upper, fore;
    };
    std::vector<Try> tries;
    for (std::size_t u = 0; u < dirs.size(); ++u) {
      for (std::size_t f = 0; f < dirs.size(); ++f) {
        if (dirs[u].dot(dirs[f]) < -0.5) continue;  // folded back past the elbow's limit
        Person trial = arm_at(dirs[u], dirs[f]);
        tries.push_back({fit(trial, found.points, 2).score(), u, f});
      }
    }
    const std::size_t keep = std::min<std::size_t>(3, tries.size());
    std::partial_sort(tries.begin(), tries.begin() + static_cast<std::ptrdiff_t>(keep), tries.end(),
                      [](const Try& a, const Try& b) { return a.score < b.score; });
    for (std::size_t k = 0; k < keep; ++k) {
      Person trial = arm_at(dirs[tries[k].upper], dirs[tries[k].fore]);
      const auto f = fit(trial, found.points, opt.init_iterations / 2);
      if (f.score() < best_fit.score() - 1e-3) {
        best_fit = f;
        p.pose = trial.pose;
        p.support = trial.support;
      }
    }
  }
  return best_fit;
}

// Continues and starts people from this frame's person-shaped groups (world
// frame) and returns the people seen, world frame. `viewpoints`: where the
// sensors that saw them are (the first one decides which way a new person is
// assumed to face on a tie).
std::vector<skeleton::Skeleton> DepthTracker::Impl::step(std::vector<PersonPoints> found, std::int64_t stamp_ns,
                                                         const std::vector<Vector3d>& viewpoints) {
  stats.regions += found.size();
  // Continue people whose pelvis is near a region (nearest first), start new ones for the rest.
  std::vector<bool> used(found.size(), false);
  for (auto& person : people) {
    const Vector3d pel = pelvis_of(person.pose);
    double best = opt.match_radius_m;
    int which = -1;
    for (std::size_t c = 0; c < found.size(); ++c) {
      if (used[c]) continue;
      const double dist = std::hypot(found[c].centre.x() - pel.x(), found[c].centre.z() - pel.z());
      if (dist < best) {
        best = dist;
        which = static_cast<int>(c);
      }
    }
    if (which < 0) continue;
    used[static_cast<std::size_t>(which)] = true;
    stats.mean_residual_m = fit(person, found[static_cast<std::size_t>(which)].points, opt.iterations).mean_abs;
    person.last_seen_ns = stamp_ns;
  }
  for (std::size_t c = 0; c < found.size(); ++c) {
    if (used[c]) continue;
    // The height is the head's top above the floor. (Cut off below, a close
    // view's floor is out of sight and so its height only as good as the
    // sensor's assumed pose: trying several heights and keeping the best
    // fit was tried on ../shared/data/skeltrack-depth, and the fits did not
    // settle on one person's size.)
    Person p;
    const auto best_fit = start(p, found[c], viewpoints.front(), std::clamp(found[c].crown, 1.0, 2.3));
    p.id = next_id++;
    stats.mean_residual_m = best_fit.mean_abs;
    p.last_seen_ns = stamp_ns;
    ++stats.initialisations;
    people.push_back(std::move(p));
  }
  // Forget people not seen for a while.
  const auto lost_ns = static_cast<std::int64_t>(opt.lost_after_s * 1e9);
  people.erase(std::remove_if(people.begin(), people.end(),
                              [&](const Person& p) {
                                if (stamp_ns - p.last_seen_ns <= lost_ns) return false;
                                dropped.push_back(p.id);
                                return true;
                              }),
               people.end());

  std::vector<skeleton::Skeleton> out;
  for (const auto& person : people) {
    if (person.last_seen_ns != stamp_ns) continue;
    skeleton::Skeleton s;
    s.person_id = person.id;
    s.stamp_ns = stamp_ns;
    s.frame_id = "world";
    // Seen from the side (the shoulder line within 45 degrees of the line of
    // sight) by every sensor, a body's front and back look alike: which arm
    // is left is a guess.
    Vector3d across = person.pose[idx(JointId::LeftShoulder)] - person.pose[idx(JointId::RightShoulder)];
    across.y() = 0.0;
    bool side_on = true;
    for (const auto& v : viewpoints) {
      Vector3d sight = person.pose[idx(JointId::Neck)] - v;
      sight.y() = 0.0;
      side_on = side_on && across.norm() > 1e-6 && sight.norm() > 1e-6 &&
                std::abs(across.normalized().dot(sight.normalized())) > std::cos(M_PI / 4.0);
    }
    for (std::size_t k = 0; k < kJ; ++k) {
      s.joints[k].position = person.pose[k];
      const bool sided = skeleton::mirror(skeleton::joint_at(k)) != skeleton::joint_at(k);
      if (side_on && sided) {
        s.joints[k].confidence = skeleton::kLost;  // reported, but no side can be vouched for
      } else {
        s.joints[k].confidence = person.support[k] >= opt.tracked_support ? skeleton::kTracked : skeleton::kInferred;
      }
    }
    out.push_back(std::move(s));
  }
  stats.people_reported += out.size();
  return out;
}

bool on_surface(const depth::DepthImage& image, const Eigen::Vector3d& joint, double margin_m) {
  if (joint.z() <= 0) return false;
  const auto px = depth::project(image.intrinsics, joint);
  const long u = std::lround(px.x()), v = std::lround(px.y());
  if (u < 0 || v < 0 || u >= image.width() || v >= image.height()) return false;
  const auto mm = image.mm[static_cast<std::size_t>(v) * static_cast<std::size_t>(image.width()) + static_cast<std::size_t>(u)];
  return mm > 0 && joint.z() >= mm * 1e-3 - margin_m;
}

std::vector<skeleton::Skeleton> DepthTracker::track(const depth::DepthImage& image) {
  depth::check(image);
  auto& d = *impl_;
  ++d.stats.frames;
  d.views = {{&image, d.world_from_sensor.inverse()}};
  auto out = d.step(find_people(image, d.world_from_sensor, d.opt), image.stamp_ns, {d.world_from_sensor.translation()});
  d.views.clear();
  const Eigen::Isometry3d sensor_from_world = d.world_from_sensor.inverse();
  for (auto& s : out) {
    s.sensor_id = image.sensor_id;
    s.frame_id = image.sensor_id;
    s.frame_number = image.frame_number;
    for (auto& j : s.joints) {
      j.position = sensor_from_world * j.position;
      // Outside the image (legs below a close view's lower edge): not seen at all.
      const auto px = depth::project(image.intrinsics, j.position);
      if (j.position.z() <= 0 || px.x() < 0 || px.y() < 0 || px.x() >= image.width() || px.y() >= image.height())
        j.confidence = skeleton::kLost;
    }
  }
  return out;
}

std::vector<skeleton::Skeleton> DepthTracker::track_merged(const std::vector<depth::DepthImage>& images,
                                                           const std::vector<Eigen::Isometry3d>& poses,
                                                           const std::string& id) {
  if (images.empty() || images.size() != poses.size()) {
    throw std::invalid_argument("track_merged: one pose per image, at least one image");
  }
  auto& d = *impl_;
  ++d.stats.frames;
  // Each sensor's people, then one group per person across sensors (standing within 0.5 m).
  std::vector<PersonPoints> merged;
  std::vector<Vector3d> viewpoints;
  std::int64_t stamp = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    viewpoints.push_back(poses[i].translation());
    stamp = std::max(stamp, images[i].stamp_ns);
    for (auto& p : find_people(images[i], poses[i], d.opt)) {
      PersonPoints* home = nullptr;
      for (auto& m : merged) {
        if (std::hypot(m.centre.x() - p.centre.x(), m.centre.z() - p.centre.z()) < 0.5) home = &m;
      }
      if (home == nullptr) {
        merged.push_back(std::move(p));
        continue;
      }
      const double n0 = static_cast<double>(home->points.size()), n1 = static_cast<double>(p.points.size());
      home->centre = (home->centre * n0 + p.centre * n1) / (n0 + n1);
      home->top = std::max(home->top, p.top);
      home->crown = std::max(home->crown, p.crown);
      home->points.insert(home->points.end(), p.points.begin(), p.points.end());
    }
  }
  for (auto& m : merged) m.points = depth::voxel_downsample(m.points, d.opt.voxel_m);
  for (std::size_t i = 0; i < images.size(); ++i) d.views.push_back({&images[i], poses[i].inverse()});
  auto out = d.step(std::move(merged), stamp, viewpoints);
  d.views.clear();
  for (auto& s : out) {
    s.sensor_id = id;
    s.frame_number = d.stats.frames;
  }
  return out;
}

}  // namespace skelgraph::depth_tracker
