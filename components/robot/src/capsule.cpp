#include "skelgraph/robot/capsule.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace skelgraph::robot {

double segment_distance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                        const Eigen::Vector3d& q1) {
  // Closest points of two segments (Ericson, Real-Time Collision Detection, 5.1.9), degenerate cases included.
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double eps = 1e-12;
  double s = 0.0, t = 0.0;
  if (a <= eps && e <= eps) return r.norm();
  if (a <= eps) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= eps) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > eps ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + s * d1) - (q0 + t * d2)).norm();
}

double capsule_distance(const Capsule& x, const Capsule& y) {
  return segment_distance(x.a, x.b, y.a, y.b) - x.radius - y.radius;
}

ClosestPair closest(const std::vector<Capsule>& xs, const std::vector<Capsule>& ys) {
  ClosestPair best{std::numeric_limits<double>::infinity(), 0, 0};
  for (std::size_t i = 0; i < xs.size(); ++i) {
    for (std::size_t k = 0; k < ys.size(); ++k) {
      const double d = capsule_distance(xs[i], ys[k]);
      if (d < best.distance) best = {d, i, k};
    }
  }
  return best;
}

}  // namespace skelgraph::robot
