#include "skelgraph/calib/cell_calib.hpp"
#include "skelgraph/skeleton/stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace skelgraph::calib {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

const CellSensor* CellCalibResult::sensor(const std::string& id) const {
  for (const auto& s : sensors)
    if (s.id == id) return &s;
  return nullptr;
}

namespace {

Matrix3d hat(const Vector3d& v) {
  Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// exp of a small motion (rotation vector, translation), applied on the left.
Isometry3d exp_left(const Eigen::Matrix<double, 6, 1>& xi) {
  Isometry3d d = Isometry3d::Identity();
  const Vector3d w = xi.head<3>();
  if (w.norm() > 0) d.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  d.translation() = xi.tail<3>();
  return d;
}

// A pair's joint pairs from matches as labelled only, when there are enough
// of them. A tracker places the joints it sees from the back a few
// centimetres off along the way it takes the person to face (the reverse of
// the truth), and with the person facing one way all along that offset
// cannot be told from a shifted sensor; views of the back are used when a
// pair has nothing else.
Correspondences direct_views(Correspondences c, std::size_t enough) {
  const auto direct = static_cast<std::size_t>(std::count(c.mirrored_pair.begin(), c.mirrored_pair.end(), false));
  if (direct < enough || direct == c.reference.size()) return c;
  Correspondences out;
  out.matched = c.matched - c.mirrored;
  for (std::size_t q = 0; q < c.reference.size(); ++q) {
    if (c.mirrored_pair[q]) continue;
    out.reference.push_back(c.reference[q]);
    out.other.push_back(c.other[q]);
    out.mirrored_pair.push_back(false);
  }
  return out;
}

// The pair could not tell the sensors' sides apart, and no prior decided.
bool undecided(const CellLink& l) { return l.fit.ambiguous && !l.fit.resolved_by_prior; }

struct LinkData {
  std::size_t link;               // index into the result's links
  std::size_t a, b;               // sensor indices
  Correspondences corr;           // a's points, b's points
};

}  // namespace

CellCalibResult calibrate_cell(const std::map<std::string, std::vector<TimedSkeleton>>& by_sensor,
                               const std::string& reference, const CellCalibOptions& o) {
  if (!by_sensor.count(reference) || by_sensor.at(reference).empty()) {
    throw CalibError("no skeletons of the reference sensor '" + reference + "'");
  }
  CellCalibResult r;
  r.reference = reference;
  std::vector<std::string> ids{reference};
  for (const auto& [id, v] : by_sensor)
    if (id != reference && !v.empty()) ids.push_back(id);
  const std::size_t n = ids.size();
  if (n < 2) throw CalibError("only the reference sensor has skeletons");
  SkeletonCalibOptions po = o.pair;
  po.max_clock_offset_ns = 0;

  // 1. Each pair on its own.
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = i + 1; k < n; ++k) {
      CellLink l;
      l.a = ids[i];
      l.b = ids[k];
      po.prior.reset();
      if (o.prior.count(l.a) && o.prior.count(l.b)) po.prior = o.prior.at(l.a).inverse() * o.prior.at(l.b);
      try {
        l.fit = calibrate_from_skeletons(by_sensor.at(l.a), by_sensor.at(l.b), po);
        l.solved = true;
      } catch (const CalibError& e) {
        l.error = e.what();
      }
      r.links.push_back(std::move(l));
    }
  }
  const auto link_index = [&](std::size_t i, std::size_t k) {
    if (i > k) std::swap(i, k);
    // Pairs (i, k), i < k, in the order made above.
    return i * n - i * (i + 1) / 2 + (k - i - 1);
  };

  // 2. Placed from the reference along the pairs that share the most (Prim).
  std::vector<Isometry3d> pose(n, Isometry3d::Identity());  // reference_from_sensor
  std::vector<bool> placed(n, false), ambiguous(n, false);
  std::vector<std::vector<std::string>> path(n);
  placed[0] = true;
  path[0] = {reference};
  for (;;) {
    // A pair that cannot tell the sensors' sides apart (turning on the spot) only when no other reaches.
    std::size_t best_from = n, best_to = n;
    std::pair<bool, std::size_t> best{false, 0};
    for (std::size_t i = 0; i < n; ++i) {
      if (!placed[i]) continue;
      for (std::size_t k = 0; k < n; ++k) {
        if (placed[k]) continue;
        const auto& l = r.links[link_index(i, k)];
        if (!l.solved || l.fit.inliers < o.min_link_pairs) continue;
        const std::pair<bool, std::size_t> key{!undecided(l), l.fit.inliers};
        if (key > best) best = key, best_from = i, best_to = k;
      }
    }
    if (best_to == n) break;
    auto& l = r.links[link_index(best_from, best_to)];
    l.in_tree = true;
    const Isometry3d a_from_b = l.fit.fit.transform();
    // The link holds (smaller index) a_from_b (larger index).
    const Isometry3d from_from_to = best_from < best_to ? a_from_b : a_from_b.inverse();
    pose[best_to] = pose[best_from] * from_from_to;
    placed[best_to] = true;
    ambiguous[best_to] = ambiguous[best_from] || undecided(l);
    path[best_to] = path[best_from];
    path[best_to].push_back(ids[best_to]);
  }
  if (std::count(placed.begin(), placed.end(), true) < 2) {
    std::string why;
    for (const auto& l : r.links) {
      if (l.a == reference) why += "; " + l.b + ": " + (l.solved ? std::to_string(l.fit.inliers) + " joint pairs" : l.error);
    }
    throw CalibError("no sensor shares enough views with the reference '" + reference + "' (" +
                     std::to_string(o.min_link_pairs) + " joint pairs needed" + why + ")");
  }

  // 3. The joint solution: unknowns are the placed sensors but the reference.
  std::vector<int> unknown(n, -1);
  int m = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (placed[i]) unknown[i] = m++;
  std::vector<LinkData> data;
  for (int round = 0; round < o.rounds; ++round) {
    r.rounds = round + 1;
    data.clear();
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = i + 1; k < n; ++k) {
        if (!placed[i] || !placed[k]) continue;
        LinkData d{link_index(i, k), i, k,
                   direct_views(correspondences(by_sensor.at(ids[i]), by_sensor.at(ids[k]), pose[i].inverse() * pose[k], po),
                                o.min_link_pairs)};
        if (d.corr.reference.size() >= o.min_link_pairs) data.push_back(std::move(d));
      }
    }
    double moved = 0;
    for (int it = 0; it < 5; ++it) {
      Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6 * m, 6 * m);
      Eigen::VectorXd g = Eigen::VectorXd::Zero(6 * m);
      for (const auto& d : data) {
        const int ua = unknown[d.a], ub = unknown[d.b];
        for (std::size_t q = 0; q < d.corr.reference.size(); ++q) {
          const Vector3d ya = pose[d.a] * d.corr.reference[q];
          const Vector3d yb = pose[d.b] * d.corr.other[q];
          const Vector3d e = ya - yb;
          const double s = e.norm() / o.pair.robust_scale_m;
          const double w = o.pair.robust_scale_m > 0 ? 1.0 / (1.0 + s * s) : 1.0;
          Eigen::Matrix<double, 3, 6> Ja, Jb;
          Ja << -hat(ya), Matrix3d::Identity();
          Jb << hat(yb), -Matrix3d::Identity();
          if (ua >= 0) {
            H.block<6, 6>(6 * ua, 6 * ua) += w * Ja.transpose() * Ja;
            g.segment<6>(6 * ua) += w * Ja.transpose() * e;
          }
          if (ub >= 0) {
            H.block<6, 6>(6 * ub, 6 * ub) += w * Jb.transpose() * Jb;
            g.segment<6>(6 * ub) += w * Jb.transpose() * e;
          }
          if (ua >= 0 && ub >= 0) {
            H.block<6, 6>(6 * ua, 6 * ub) += w * Ja.transpose() * Jb;
            H.block<6, 6>(6 * ub, 6 * ua) += w * Jb.transpose() * Ja;
          }
        }
      }
      // A sensor no used link reaches keeps its pose (a tiny damping keeps H invertible).
      H.diagonal().array() += 1e-9;
      const Eigen::VectorXd dx = H.ldlt().solve(-g);
      double step = 0;
      for (std::size_t i = 1; i < n; ++i) {
        if (unknown[i] < 0) continue;
        const Eigen::Matrix<double, 6, 1> xi = dx.segment<6>(6 * unknown[i]);
        pose[i] = exp_left(xi) * pose[i];
        step = std::max(step, xi.head<3>().norm() * 180.0 / M_PI * 0.01 + xi.tail<3>().norm());
      }
      moved = std::max(moved, step);
      if (step < 1e-7) break;
    }
    if (round > 0 && moved < 1e-6) break;
  }

  // The figures under the final poses.
  std::vector<std::vector<double>> per_sensor(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = i + 1; k < n; ++k) {
      auto& l = r.links[link_index(i, k)];
      l.median_m = std::nan("");
      if (!placed[i] || !placed[k]) continue;
      const auto c = direct_views(correspondences(by_sensor.at(ids[i]), by_sensor.at(ids[k]), pose[i].inverse() * pose[k], po),
                                  o.min_link_pairs);
      if (c.reference.size() < o.min_link_pairs) continue;
      std::vector<double> d;
      for (std::size_t q = 0; q < c.reference.size(); ++q) d.push_back((pose[i] * c.reference[q] - pose[k] * c.other[q]).norm());
      l.pairs = d.size();
      l.mirrored = c.mirrored;
      l.median_m = stats::upper_median(d);
      per_sensor[i].insert(per_sensor[i].end(), d.begin(), d.end());
      per_sensor[k].insert(per_sensor[k].end(), d.begin(), d.end());
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    CellSensor s;
    s.id = ids[i];
    s.placed = placed[i];
    s.ambiguous = ambiguous[i];
    s.reference_from_sensor = pose[i];
    s.path = path[i];
    s.pairs = per_sensor[i].size();
    s.median_m = stats::upper_median(per_sensor[i]);
    double sq = 0;
    for (const double d : per_sensor[i]) sq += d * d, s.max_m = std::max(s.max_m, d);
    s.rms_m = per_sensor[i].empty() ? std::nan("") : std::sqrt(sq / static_cast<double>(per_sensor[i].size()));
    r.sensors.push_back(std::move(s));
  }
  return r;
}

}  // namespace skelgraph::calib
