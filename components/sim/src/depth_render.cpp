#include "skelgraph/sim/depth_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace skelgraph::sim {

using skeleton::JointId;

std::vector<Capsule> body_capsules(const skeleton::Skeleton& s, double height_m, double girth) {
  const double k = height_m / 1.75 * girth;
  const double head_k = height_m / 1.75;
  const auto p = [&](JointId j) { return s[j].position; };
  const Eigen::Vector3d hip_centre = 0.5 * (p(JointId::LeftHip) + p(JointId::RightHip));
  std::vector<Capsule> c = {
      {p(JointId::Head), p(JointId::Head), 0.095 * head_k},
      {p(JointId::Neck), p(JointId::Head), 0.055 * k},
      {p(JointId::LeftShoulder), p(JointId::RightShoulder), 0.06 * k},
      {p(JointId::LeftShoulder), p(JointId::LeftHip), 0.085 * k},
      {p(JointId::RightShoulder), p(JointId::RightHip), 0.085 * k},
      {p(JointId::Neck), p(JointId::Torso), 0.10 * k},
      {p(JointId::Torso), hip_centre, 0.11 * k},
      {p(JointId::LeftHip), p(JointId::RightHip), 0.09 * k},
      {p(JointId::LeftShoulder), p(JointId::LeftElbow), 0.045 * k},
      {p(JointId::RightShoulder), p(JointId::RightElbow), 0.045 * k},
      {p(JointId::LeftElbow), p(JointId::LeftHand), 0.038 * k},
      {p(JointId::RightElbow), p(JointId::RightHand), 0.038 * k},
      {p(JointId::LeftHand), p(JointId::LeftHand), 0.05 * k},
      {p(JointId::RightHand), p(JointId::RightHand), 0.05 * k},
      {p(JointId::LeftHip), p(JointId::LeftKnee), 0.075 * k},
      {p(JointId::RightHip), p(JointId::RightKnee), 0.075 * k},
      {p(JointId::LeftKnee), p(JointId::LeftFoot), 0.05 * k},
      {p(JointId::RightKnee), p(JointId::RightFoot), 0.05 * k},
      {p(JointId::LeftFoot), p(JointId::LeftFoot), 0.05 * k},
      {p(JointId::RightFoot), p(JointId::RightFoot), 0.05 * k},
  };
  return c;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// First t > 0 where the ray t*d (from the origin) enters the sphere, else inf.
double hit_sphere(const Eigen::Vector3d& d, double dd, const Eigen::Vector3d& c, double r) {
  const double dc = d.dot(c);
  const double h = dc * dc - dd * (c.squaredNorm() - r * r);
  if (h < 0) return kInf;
  const double t = (dc - std::sqrt(h)) / dd;
  return t > 0 ? t : kInf;
}

// First t > 0 where the ray t*d enters the capsule (cylinder side or either cap).
double hit_capsule(const Eigen::Vector3d& d, const Capsule& cap) {
  const double dd = d.squaredNorm();
  double best = std::min(hit_sphere(d, dd, cap.a, cap.radius), hit_sphere(d, dd, cap.b, cap.radius));
  const Eigen::Vector3d ba = cap.b - cap.a;
  const double baba = ba.squaredNorm();
  if (baba < 1e-12) return best;
  const Eigen::Vector3d oa = -cap.a;
  const double bard = ba.dot(d), baoa = ba.dot(oa), rdoa = d.dot(oa), oaoa = oa.squaredNorm();
  const double A = baba * dd - bard * bard;
  const double B = baba * rdoa - baoa * bard;
  const double C = baba * oaoa - baoa * baoa - cap.radius * cap.radius * baba;
  const double h = B * B - A * C;
  if (A > 1e-12 && h >= 0) {
    const double t = (-B - std::sqrt(h)) / A;
    const double y = baoa + t * bard;
    if (t > 0 && y > 0 && y < baba) best = std::min(best, t);
  }
  return best;
}

// Where the ray o + t*d enters the box (t > 0), else inf.
double hit_box_outside(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::AlignedBox3d& box) {
  double t0 = 0.0, t1 = kInf;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (o[i] < box.min()[i] || o[i] > box.max()[i]) return kInf;
      continue;
    }
    double a = (box.min()[i] - o[i]) / d[i], b = (box.max()[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return kInf;
  }
  return t0 > 0 ? t0 : kInf;
}

// Where the ray o + t*d leaves the box it starts inside (walls, floor, ceiling).
double hit_box_inside(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::AlignedBox3d& box) {
  double t = kInf;
  for (int i = 0; i < 3; ++i) {
    if (d[i] > 1e-12) t = std::min(t, (box.max()[i] - o[i]) / d[i]);
    if (d[i] < -1e-12) t = std::min(t, (box.min()[i] - o[i]) / d[i]);
  }
  return t > 0 ? t : kInf;
}

}  // namespace

DepthRenderer::DepthRenderer(const SensorConfig& sensor, const calib::Intrinsics& k, DepthNoise noise, Room room)
    : view_(sensor), k_(k), noise_(noise), room_(room) {
  if (k.width <= 0 || k.height <= 0 || k.width > 4096 || k.height > 4096) {
    throw std::invalid_argument("depth renderer: image size must be 1-4096 pixels a side");
  }
  if (!(k.fx > 0) || !(k.fy > 0)) throw std::invalid_argument("depth renderer: focal lengths must be positive");
  if (!(noise.focal_px > 0) || !(noise.baseline_m > 0) || !(noise.disparity_step_px >= 0) ||
      !(noise.disparity_sd_px >= 0) || !(noise.min_range_m >= 0) || !(noise.max_range_m > noise.min_range_m) ||
      !(noise.edge_drop >= 0 && noise.edge_drop <= 1) || !(noise.random_drop >= 0 && noise.random_drop <= 1)) {
    throw std::invalid_argument("depth renderer: bad noise settings");
  }
  rays_.reserve(static_cast<std::size_t>(k.width) * k.height);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) rays_.push_back(depth::unproject(k, u, v, 1.0));
  }
}

std::vector<float> DepthRenderer::render_exact(const std::vector<skeleton::Skeleton>& people,
                                               const std::vector<Obstacle>& obstacles, double height_m,
                                               double girth) const {
  const int w = k_.width, h = k_.height;
  std::vector<double> zbuf(rays_.size(), kInf);
  const Eigen::Isometry3d world_from_sensor = view_.config().world_from_sensor();
  const Eigen::Matrix3d R = world_from_sensor.linear();
  const Eigen::Vector3d o = world_from_sensor.translation();

  // Room (walls, floor, ceiling) or, without a room, the floor plane; then the props.
  for (std::size_t i = 0; i < rays_.size(); ++i) {
    const Eigen::Vector3d d = R * rays_[i];
    double t = kInf;
    if (room_.enabled) {
      t = hit_box_inside(o, d, room_.box);
    } else if (d.y() < -1e-12) {
      t = -o.y() / d.y();
    }
    for (const auto& ob : obstacles) t = std::min(t, hit_box_outside(o, d, ob.box));
    zbuf[i] = t;  // rays have z = 1 in the sensor frame, so t is the depth
  }

  // People: each capsule only over the pixels its end spheres can cover.
  const Eigen::Isometry3d sensor_from_world = view_.sensor_from_world();
  for (const auto& person : people) {
    for (auto cap : body_capsules(person, height_m, girth)) {
      cap.a = sensor_from_world * cap.a;
      cap.b = sensor_from_world * cap.b;
      int u0 = 0, u1 = w - 1, v0 = 0, v1 = h - 1;
      const double near = cap.radius + 0.05;
      if (cap.a.z() > near && cap.b.z() > near) {
        double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
        for (const auto& e : {cap.a, cap.b}) {
          const Eigen::Vector2d px = depth::project(k_, e);
          const double rx = k_.fx * cap.radius / (e.z() - cap.radius) + 2.0;
          const double ry = k_.fy * cap.radius / (e.z() - cap.radius) + 2.0;
          umin = std::min(umin, px.x() - rx);
          umax = std::max(umax, px.x() + rx);
          vmin = std::min(vmin, px.y() - ry);
          vmax = std::max(vmax, px.y() + ry);
        }
        if (umax < 0 || vmax < 0 || umin > w - 1 || vmin > h - 1) continue;
        u0 = std::max(0, static_cast<int>(std::floor(umin)));
        u1 = std::min(w - 1, static_cast<int>(std::ceil(umax)));
        v0 = std::max(0, static_cast<int>(std::floor(vmin)));
        v1 = std::min(h - 1, static_cast<int>(std::ceil(vmax)));
      } else if (cap.a.z() <= 0 && cap.b.z() <= 0) {
        continue;  // behind the sensor
      }
      for (int v = v0; v <= v1; ++v) {
        for (int u = u0; u <= u1; ++u) {
          const auto i = static_cast<std::size_t>(v) * w + u;
          const double t = hit_capsule(rays_[i], cap);
          if (t < zbuf[i]) zbuf[i] = t;
        }
      }
    }
  }
  std::vector<float> out(zbuf.size(), 0.0f);
  for (std::size_t i = 0; i < zbuf.size(); ++i) out[i] = std::isfinite(zbuf[i]) ? static_cast<float>(zbuf[i]) : 0.0f;
  return out;
}

depth::DepthImage DepthRenderer::render(const std::vector<skeleton::Skeleton>& people,
                                        const std::vector<Obstacle>& obstacles, Rng& rng, double height_m,
                                        double girth) const {
  const auto exact = render_exact(people, obstacles, height_m, girth);
  auto image = depth::DepthImage::blank(k_);
  image.sensor_id = view_.config().id;
  const int w = k_.width, h = k_.height;
  const double fb = noise_.focal_px * noise_.baseline_m;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const auto i = static_cast<std::size_t>(v) * w + u;
      double z = exact[i];
      if (z <= 0) continue;
      if (noise_.enabled) {
        if (rng.chance(noise_.random_drop)) continue;
        // A neighbour clearly nearer: the pixel sits on the far side of a depth edge.
        bool edge = false;
        for (const auto& [du, dv] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
          const float zn = exact[static_cast<std::size_t>(vv) * w + uu];
          if (zn > 0 && zn < z - noise_.edge_jump_m) edge = true;
        }
        if (edge && rng.chance(noise_.edge_drop)) continue;
        double disparity = fb / z + rng.normal(0.0, noise_.disparity_sd_px);
        if (noise_.disparity_step_px > 0) {
          disparity = std::round(disparity / noise_.disparity_step_px) * noise_.disparity_step_px;
        }
        if (disparity <= 0) continue;
        z = fb / disparity;
      }
      if (z < noise_.min_range_m || z > noise_.max_range_m) continue;
      image.mm[i] = static_cast<std::uint16_t>(std::lround(z * 1000.0));
    }
  }
  return image;
}

}  // namespace skelgraph::sim
