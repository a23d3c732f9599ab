#include "skelgraph/calib/rigid.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include <Eigen/SVD>

namespace skelgraph::calib {

using Eigen::Matrix3d;
using Eigen::Vector3d;

Eigen::Isometry3d Alignment::transform() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

namespace {

void check_inputs(const std::vector<Vector3d>& a, const std::vector<Vector3d>& b, const std::vector<double>& w) {
  if (a.size() != b.size()) {
    throw CalibError("point sets differ in size (" + std::to_string(a.size()) + " and " + std::to_string(b.size()) + ")");
  }
  if (a.size() < 3) throw CalibError("need at least 3 point pairs, got " + std::to_string(a.size()));
  if (!w.empty() && w.size() != a.size()) {
    throw CalibError(std::to_string(w.size()) + " weights for " + std::to_string(a.size()) + " point pairs");
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i].allFinite() || !b[i].allFinite()) throw CalibError("point pair " + std::to_string(i) + " is not finite (NaN or inf)");
    if (!w.empty() && (!std::isfinite(w[i]) || w[i] < 0)) {
      throw CalibError("weight " + std::to_string(i) + " is negative or not finite");
    }
  }
}

}  // namespace

Alignment align(const std::vector<Vector3d>& a, const std::vector<Vector3d>& b, const std::vector<double>& weights,
                const AlignOptions& options) {
  check_inputs(a, b, weights);
  const std::size_t n = a.size();
  auto w = [&](std::size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  double wsum = 0;
  std::size_t positive = 0;
  Vector3d ca = Vector3d::Zero(), cb = Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    wsum += w(i);
    positive += w(i) > 0 ? 1 : 0;
    ca += w(i) * a[i];
    cb += w(i) * b[i];
  }
  if (positive < 3) throw CalibError("need at least 3 point pairs with weight > 0, got " + std::to_string(positive));
  ca /= wsum;
  cb /= wsum;
  Matrix3d H = Matrix3d::Zero(), Sa = Matrix3d::Zero(), Sb = Matrix3d::Zero();
  double var_a = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vector3d da = a[i] - ca, db = b[i] - cb;
    H += w(i) * da * db.transpose();
    Sa += w(i) * da * da.transpose();
    Sb += w(i) * db * db.transpose();
    var_a += w(i) * da.squaredNorm();
  }
  // Both sets must span at least a plane: on a line the rotation about it is free.
  for (const Matrix3d* S : {&Sa, &Sb}) {
    const Eigen::JacobiSVD<Matrix3d> spread(*S);
    const auto sv = spread.singularValues();
    if (sv(0) <= 0 || sv(1) <= options.collinear_tolerance * sv(0)) {
      throw CalibError(sv(0) <= 0 ? "the points all coincide" : "the points are collinear: the rotation about their line is undetermined");
    }
  }
  const Eigen::JacobiSVD<Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Matrix3d U = svd.matrixU(), V = svd.matrixV();
  Matrix3d D = Matrix3d::Identity();
  if ((V * U.transpose()).determinant() < 0) D(2, 2) = -1;  // the best orthogonal fit is a reflection: flip the weakest axis
  Alignment out;
  out.R = V * D * U.transpose();
  if (options.with_scale) {
    out.scale = (svd.singularValues().asDiagonal() * D).trace() / var_a;
    if (!(out.scale > 0)) throw CalibError("the scale came out non-positive: the point sets do not correspond");
  }
  out.t = cb - out.scale * out.R * ca;
  out.residuals = residuals(out, a, b);
  double ss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ss += w(i) * out.residuals[i] * out.residuals[i];
    out.max = std::max(out.max, out.residuals[i]);
  }
  out.rms = std::sqrt(ss / wsum);
  return out;
}

std::vector<double> residuals(const Alignment& fit, const std::vector<Vector3d>& a, const std::vector<Vector3d>& b) {
  std::vector<double> r(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) r[i] = (fit.apply(a[i]) - b[i]).norm();
  return r;
}

RansacResult ransac_align(const std::vector<Vector3d>& a, const std::vector<Vector3d>& b, const RansacOptions& options) {
  check_inputs(a, b, {});
  const std::size_t n = a.size();
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  const double thr = options.inlier_threshold_m;
  auto inliers_of = [&](const Alignment& f) {
    std::vector<std::size_t> in;
    for (std::size_t i = 0; i < n; ++i) {
      if ((f.apply(a[i]) - b[i]).norm() <= thr) in.push_back(i);
    }
    return in;
  };
  auto subset = [&](const std::vector<std::size_t>& idx, std::vector<Vector3d>& sa, std::vector<Vector3d>& sb) {
    sa.clear();
    sb.clear();
    for (auto i : idx) sa.push_back(a[i]), sb.push_back(b[i]);
  };
  RansacResult best;
  double best_rms = 0;
  int needed = options.max_iterations;
  std::vector<Vector3d> sa, sb;
  int it = 0;
  for (; it < options.max_iterations && it < needed; ++it) {
    const std::size_t i = pick(rng), j = pick(rng), k = pick(rng);
    if (i == j || j == k || i == k) continue;
    Alignment f;
    try {
      f = align({a[i], a[j], a[k]}, {b[i], b[j], b[k]}, {}, options.align);
    } catch (const CalibError&) {
      continue;  // a collinear sample
    }
    auto in = inliers_of(f);
    if (in.size() < 3) continue;
    double ss = 0;
    for (auto x : in) ss += (f.apply(a[x]) - b[x]).squaredNorm();
    const double rms = std::sqrt(ss / static_cast<double>(in.size()));
    if (in.size() > best.inliers.size() || (in.size() == best.inliers.size() && rms < best_rms)) {
      best.inliers = std::move(in);
      best.fit = f;
      best_rms = rms;
      // Adaptive stop: the chance that all 3 points of a sample are inliers.
      const double p = static_cast<double>(best.inliers.size()) / static_cast<double>(n);
      const double p3 = std::min(1.0 - 1e-12, p * p * p);
      needed = static_cast<int>(std::ceil(std::log(1.0 - options.confidence) / std::log(1.0 - p3)));
    }
  }
  best.iterations = it;
  if (best.inliers.size() < std::max<std::size_t>(3, options.min_inliers)) {
    throw CalibError("no consistent subset: the best model had " + std::to_string(best.inliers.size()) + " of " +
                     std::to_string(n) + " pairs within " + std::to_string(thr) + " m");
  }
  // Refit on the inliers until the inlier set stops changing.
  for (int round = 0; round < 10; ++round) {
    subset(best.inliers, sa, sb);
    Alignment f;
    try {
      f = align(sa, sb, {}, options.align);
    } catch (const CalibError&) {
      break;
    }
    auto in = inliers_of(f);
    if (in.size() < 3) break;
    const bool same = in == best.inliers;
    best.fit = f;
    best.inliers = std::move(in);
    if (same) break;
  }
  subset(best.inliers, sa, sb);
  best.fit.residuals = residuals(best.fit, sa, sb);
  double ss = 0;
  best.fit.max = 0;
  for (double r : best.fit.residuals) ss += r * r, best.fit.max = std::max(best.fit.max, r);
  best.fit.rms = std::sqrt(ss / static_cast<double>(best.fit.residuals.size()));
  return best;
}

double rotation_angle_deg(const Matrix3d& R) {
  const double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

Eigen::Matrix3d sensor_from_camera() { return Eigen::Vector3d(-1, -1, 1).asDiagonal(); }

RansacResult pose_from_views(const std::vector<std::vector<Eigen::Vector3d>>& a, const std::vector<std::vector<Eigen::Vector3d>>& b) {
  if (a.size() != b.size()) throw CalibError("the two sets have different numbers of views");
  std::vector<Eigen::Vector3d> pa, pb;
  for (std::size_t v = 0; v < a.size(); ++v) {
    if (a[v].size() != b[v].size()) throw CalibError("view " + std::to_string(v) + ": different corner counts");
    pa.insert(pa.end(), a[v].begin(), a[v].end());
    pb.insert(pb.end(), b[v].begin(), b[v].end());
  }
  RansacOptions o;
  o.inlier_threshold_m = 0.02;
  o.min_inliers = 6;
  return ransac_align(pb, pa, o);
}

}  // namespace skelgraph::calib
