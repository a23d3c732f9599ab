#include "skelgraph/calib/robot_calib.hpp"
#include "skelgraph/skeleton/stats.hpp"

#include <algorithm>


namespace skelgraph::calib {

using Eigen::Vector3d;

RobotFit fit_board_on_tool(const std::vector<std::vector<Vector3d>>& corners_camera,
                           const std::vector<Eigen::Isometry3d>& base_from_board,
                           const std::vector<Vector3d>& object_points) {
  if (corners_camera.size() != base_from_board.size()) {
    throw CalibError(std::to_string(corners_camera.size()) + " views of corners but " +
                     std::to_string(base_from_board.size()) + " tool poses");
  }
  if (corners_camera.size() < 3) {
    throw CalibError("the board on the tool was usable in only " + std::to_string(corners_camera.size()) + " views (need 3)");
  }
  std::vector<std::vector<Vector3d>> in_base;
  RobotFit out;
  for (std::size_t v = 0; v < corners_camera.size(); ++v) {
    if (corners_camera[v].size() != object_points.size()) {
      throw CalibError("view " + std::to_string(v) + ": " + std::to_string(corners_camera[v].size()) + " corners, the board has " +
                       std::to_string(object_points.size()));
    }
    std::vector<Vector3d> b;
    for (const auto& p : object_points) b.push_back(base_from_board[v] * p);
    in_base.push_back(std::move(b));
    out.points += object_points.size();
  }
  out.views = corners_camera.size();
  out.ransac = pose_from_views(in_base, corners_camera);  // camera -> base
  // Camera frame (x right, y down) -> skelgraph sensor frame (x left, y up).
  out.base_from_sensor = Eigen::Isometry3d::Identity();
  out.base_from_sensor.linear() = out.ransac.fit.R * sensor_from_camera().transpose();
  out.base_from_sensor.translation() = out.ransac.fit.t;
  return out;
}

namespace {

// Per axis, the upper median (stats.hpp).
Vector3d median(const std::vector<Vector3d>& pts) {
  Vector3d m;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> c;
    c.reserve(pts.size());
    for (const auto& p : pts) c.push_back(p[i]);
    m[i] = stats::upper_median(std::move(c));
  }
  return m;
}

// Stretches [first, last] of a series in which every point stays within
// `radius` of the stretch's running mean, no two samples more than `max_gap_ns`
// apart (a tracker that lost the hand), lasting at least `min_ns`.
std::vector<std::pair<std::size_t, std::size_t>> still_stretches(const std::vector<TimedPoint>& s, std::size_t from,
                                                                 std::size_t to, double radius, std::int64_t min_ns,
                                                                 std::int64_t max_gap_ns) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  std::size_t i = from;
  while (i < to) {
    Vector3d sum = s[i].p;
    std::size_t j = i + 1;
    while (j < to && s[j].t_ns - s[j - 1].t_ns <= max_gap_ns && (s[j].p - sum / static_cast<double>(j - i)).norm() <= radius) {
      sum += s[j].p;
      ++j;
    }
    if (s[j - 1].t_ns - s[i].t_ns >= min_ns) {
      out.emplace_back(i, j - 1);
      i = j;
    } else {
      ++i;
    }
  }
  return out;
}

}  // namespace

std::vector<Hold> find_holds(const std::vector<TimedPoint>& tool, const std::vector<TimedPoint>& hand,
                             const HoldOptions& o) {
  const auto min_ns = static_cast<std::int64_t>(o.hold_s * 1e9);
  std::vector<Hold> holds;
  for (const auto& [a, b] : still_stretches(tool, 0, tool.size(), 0.5 * o.tool_still_m, min_ns, o.max_gap_ns)) {
    const std::int64_t t0 = tool[a].t_ns - o.max_skew_ns, t1 = tool[b].t_ns + o.max_skew_ns;
    const auto lo = std::lower_bound(hand.begin(), hand.end(), t0, [](const TimedPoint& p, std::int64_t t) { return p.t_ns < t; });
    const auto hi = std::upper_bound(hand.begin(), hand.end(), t1, [](std::int64_t t, const TimedPoint& p) { return t < p.t_ns; });
    const auto h0 = static_cast<std::size_t>(lo - hand.begin()), h1 = static_cast<std::size_t>(hi - hand.begin());
    // The hand's longest still stretch while the tool stands.
    std::pair<std::size_t, std::size_t> best{0, 0};
    std::int64_t best_ns = -1;
    for (const auto& st : still_stretches(hand, h0, h1, 0.5 * o.hand_still_m, min_ns, o.max_gap_ns)) {
      const auto ns = hand[st.second].t_ns - hand[st.first].t_ns;
      if (ns > best_ns) best = st, best_ns = ns;
    }
    if (best_ns < 0) continue;
    Hold h;
    h.start_ns = std::max(hand[best.first].t_ns, tool[a].t_ns);
    h.end_ns = std::min(hand[best.second].t_ns, tool[b].t_ns);
    std::vector<Vector3d> tp, hp;
    for (std::size_t i = a; i <= b; ++i) tp.push_back(tool[i].p);
    for (std::size_t i = best.first; i <= best.second; ++i) hp.push_back(hand[i].p);
    h.tool = median(tp);
    h.hand = median(hp);
    h.hand_samples = hp.size();
    if (!holds.empty() && (holds.back().tool - h.tool).norm() < o.min_gap_m) continue;  // the same pose again
    holds.push_back(h);
  }
  return holds;
}

RobotFit fit_hand_at_tool(const std::vector<Hold>& holds, double inlier_m) {
  if (holds.size() < 4) {
    throw CalibError("only " + std::to_string(holds.size()) + " moments with the hand held still at a still tool (need 4 or more, at different places)");
  }
  std::vector<Vector3d> hand, tool;
  for (const auto& h : holds) {
    hand.push_back(h.hand);
    tool.push_back(h.tool);
  }
  RansacOptions ro;
  ro.inlier_threshold_m = inlier_m;
  ro.min_inliers = 4;
  RobotFit out;
  out.ransac = ransac_align(hand, tool, ro);
  out.base_from_sensor = out.ransac.fit.transform();
  out.points = out.views = holds.size();
  return out;
}

std::size_t count_places(const std::vector<Hold>& holds, const std::vector<std::size_t>& which, double min_gap_m) {
  std::vector<Vector3d> places;
  for (std::size_t i : which) {
    if (std::none_of(places.begin(), places.end(), [&](const Vector3d& p) { return (p - holds[i].tool).norm() < min_gap_m; })) {
      places.push_back(holds[i].tool);
    }
  }
  return places.size();
}

HandCalibration calibrate_hand_at_tool(
    const std::vector<TimedPoint>& tool,
    const std::map<std::string, std::map<std::pair<std::uint32_t, int>, std::vector<TimedPoint>>>& hands,
    const HandCalibOptions& o) {
  HandCalibration out;
  const Eigen::Isometry3d base_from_world = o.world_from_base.inverse();
  std::map<std::string, std::vector<Hold>> by_sensor;
  for (const auto& [sensor, people] : hands) {
    auto& holds = by_sensor[sensor];
    for (const auto& [id, pts] : people) {
      const auto h = find_holds(tool, pts, o.holds);
      holds.insert(holds.end(), h.begin(), h.end());
    }
    for (auto& h : holds) h.tool = base_from_world * h.tool;
  }
  std::vector<std::string> in_cell;
  if (!o.cell.empty()) {
    std::vector<Hold> pooled;
    for (const auto& [sensor, holds] : by_sensor) {
      const auto c = o.cell.find(sensor);
      if (c == o.cell.end()) {
        out.failed.push_back(sensor + ": not in " + o.cell_name);
        continue;
      }
      for (auto h : holds) {
        h.hand = c->second * h.hand;
        pooled.push_back(h);
      }
      in_cell.push_back(sensor);
    }
    by_sensor.clear();
    by_sensor["cell"] = std::move(pooled);
  }
  for (const auto& [sensor, holds] : by_sensor) {
    try {
      HandFit r{sensor, fit_hand_at_tool(holds, o.inlier_m), holds.size()};
      std::vector<std::size_t> all(holds.size());
      for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
      r.places = count_places(holds, all, o.holds.min_gap_m);
      r.places_agreeing = count_places(holds, r.fit.ransac.inliers, o.holds.min_gap_m);
      if (o.cell.empty()) {
        out.fits.push_back(std::move(r));
        continue;
      }
      for (const auto& s : in_cell) {  // base_from_cell, then each sensor through its pose in the cell
        HandFit rs = r;
        rs.sensor = s;
        rs.fit.base_from_sensor = r.fit.base_from_sensor * o.cell.at(s);
        out.fits.push_back(std::move(rs));
      }
    } catch (const CalibError& e) {
      out.failed.push_back(sensor + ": " + e.what());
    }
  }
  return out;
}

bool board_fit_good(const RobotFit& fit) {
  return fit.ransac.fit.rms < 0.01 && fit.ransac.inliers.size() * 10 >= fit.points * 8;
}

bool hand_fit_good(const HandFit& fit) {
  return fit.fit.ransac.fit.rms < 0.04 && fit.places_agreeing * 10 >= fit.places * 8;
}

}  // namespace skelgraph::calib
