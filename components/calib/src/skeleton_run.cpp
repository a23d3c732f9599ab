#include "skelgraph/calib/skeleton_run.hpp"

#include <cmath>

#include "skelgraph/calib/calibration_step.hpp"
#include "skelgraph/calib/rigid.hpp"
#include "skelgraph/calib/skeleton_calib.hpp"
#include "skelgraph/eval/metrics.hpp"
#include "skelgraph/skeleton/json_number.hpp"
#include "skelgraph/skeleton/stats.hpp"

namespace skelgraph::calib {

nlohmann::json pose_json(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  return {{"translation_m", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
          {"rotation_deg", rotation_angle_deg(T.rotation())}};
}

double cm(double m) { return std::isfinite(m) ? std::round(m * 1000.0) / 10.0 : m; }

namespace {

// What a result says when the skeletons could not tell on which side of the person a sensor is.
const char* const kUndecided =
    "ambiguous: the person hardly moved about (turned on the spot?), so the skeletons cannot tell on which side of "
    "them the sensor is, and nothing decided: kept the previous pose (the fit's guess, the side where both sensors "
    "see the front more often, is in the JSON). Walk a loop facing where you go, or give the rough layout with --prior";

// The upper body as evaluation scores it, group by group (head, neck, torso, shoulders, elbows, hands).
std::vector<skeleton::JointId> upper_body() {
  std::vector<skeleton::JointId> upper;
  for (int g = 0; g < static_cast<int>(eval::kGroupCount); ++g)
    for (std::size_t k = 0; k < skeleton::kJointCount; ++k)
      if (eval::group_of(skeleton::joint_at(k)) == g) upper.push_back(skeleton::joint_at(k));
  return upper;
}

// Every sensor of one input at once (no --other and more than one other sensor).
nlohmann::json calibrate_cell_input(const std::string& path, const SkeletonRun& o, const SkeletonInput& in,
                                    std::vector<skeleton::SensorPose>* result) {
  SensorSkeletons fit = in.by_sensor, test;
  if (o.holdout) {
    auto halves = split_halves(in.by_sensor, o.ref);
    fit = std::move(halves.fit), test = std::move(halves.test);
  }
  // The poses the input already implies (a shared frame when it has none).
  SensorPoses before;
  for (const auto& [id, v] : in.by_sensor) {
    before[id] = in.poses.count(o.ref) && in.poses.count(id) ? Eigen::Isometry3d(in.poses.at(o.ref).inverse() * in.poses.at(id))
                                                             : Eigen::Isometry3d::Identity();
  }
  CellCalibOptions co;
  co.pair.inlier_threshold_m = o.threshold_m;
  co.pair.robust_scale_m = o.robust_scale_m;
  co.prior = in.poses;
  CellStep step;
  try {
    step = calibrate_cell_step(fit, o.ref, before, co);
  } catch (const CalibError& e) {
    throw InputError(path + ": cannot calibrate the cell against " + o.ref + ": " + e.what());
  }
  const auto& r = step.fit;
  const auto& chosen = step.chosen;
  const auto upper = upper_body();
  nlohmann::json j{{"input", path}, {"reference", o.ref}, {"mode", "cell"}, {"joint_solution_rounds", r.rounds}};
  auto& sensors = j["sensors"] = nlohmann::json::array();
  std::size_t unplaced = 0, undecided = 0;
  for (const auto& s : r.sensors) {
    if (s.id == o.ref) continue;
    nlohmann::json sj{{"sensor", s.id}, {"frames", in.by_sensor.at(s.id).size()}, {"placed", s.placed}};
    if (!s.placed) {
      ++unplaced;
      sj["verdict"] = "not placed: it shares too few views with any placed sensor; kept the previous pose";
      sj["improved"] = false;
      sensors.push_back(sj);
      continue;
    }
    // Never worse than before, sensor by sensor, on the data it was fitted to.
    const auto& acc = step.acceptance.at(s.id);
    const bool improved = acc.improved;
    sj["path"] = s.path;
    sj["reference_from_sensor"] = pose_json(s.reference_from_sensor);
    sj["joint_pairs"] = s.pairs;
    sj["median_distance_cm"] = json_number(cm(s.median_m));
    sj["rms_residual_cm"] = json_number(cm(s.rms_m));
    sj["max_residual_cm"] = json_number(cm(s.max_m));
    sj["fit_median_distance_cm"] = {{"before", json_number(cm(acc.before_m))}, {"after", json_number(cm(acc.after_m))}};
    sj["improved"] = improved;
    sj["undecided"] = s.ambiguous;
    if (s.ambiguous) ++undecided;
    sj["verdict"] = s.ambiguous ? kUndecided
                    : improved  ? "calibrated: brings its skeletons closer to the other sensors' than before"
                                : "kept the previous pose: the fit did not bring its skeletons closer on the data it saw";
    sensors.push_back(sj);
  }
  if (o.holdout) {
    for (auto& sj : sensors) {
      const auto id = sj["sensor"].get<std::string>();
      sj["held_out_median_distance_cm"] = {{"before", json_number(cm(cell_median(test, id, before, upper)))},
                                           {"after", json_number(cm(cell_median(test, id, chosen, upper)))}};
    }
  }
  auto& links = j["links"] = nlohmann::json::array();
  for (const auto& l : r.links) {
    nlohmann::json lj{{"a", l.a}, {"b", l.b}, {"solved", l.solved}, {"in_tree", l.in_tree}, {"joint_pairs", l.pairs},
                      {"mirrored_frames", l.mirrored}, {"median_distance_cm", json_number(cm(l.median_m))}};
    if (l.solved) {
      lj["ambiguous"] = l.fit.ambiguous;
      lj["resolved_by_prior"] = l.fit.resolved_by_prior;
      lj["person_spread_cm"] = cm(l.fit.person_spread_m);
    }
    if (!l.solved) lj["error"] = l.error;
    links.push_back(lj);
  }
  j["unplaced"] = unplaced;
  j["undecided"] = undecided;
  if (result != nullptr) {
    for (const auto& sj : sensors) {
      skeleton::SensorPose p;
      p.sensor_id = sj["sensor"].get<std::string>();
      p.pose = chosen.at(p.sensor_id);
      p.method = sj["improved"].get<bool>() ? "skeleton (cell)" : "unchanged";
      if (sj["improved"].get<bool>()) {
        // Its joint pairs' residuals under the joint solution.
        const auto* s = r.sensor(p.sensor_id);
        p.rms_residual_m = std::isfinite(s->rms_m) ? s->rms_m : 0.0;
        p.max_residual_m = s->max_m;
      }
      result->push_back(p);
    }
  }
  return j;
}

}  // namespace

nlohmann::json calibrate_skeletons(const std::string& path, const SkeletonInput& in, const SkeletonRun& o,
                                   std::vector<skeleton::SensorPose>* results) {
  std::string names;
  for (const auto& [id, v] : in.by_sensor) names += (names.empty() ? "" : ", ") + id + " (" + std::to_string(v.size()) + ")";
  if (!in.by_sensor.count(o.ref)) throw InputError(path + ": no skeletons of reference sensor '" + o.ref + "'; sensors: " + names);
  std::string other = o.other;
  if (other.empty()) {
    if (in.by_sensor.size() > 2) return calibrate_cell_input(path, o, in, results);
    for (const auto& [id, v] : in.by_sensor)
      if (id != o.ref) other = id;
    if (other.empty()) throw InputError(path + ": only the reference sensor has skeletons (" + names + ")");
  } else if (!in.by_sensor.count(other)) {
    throw InputError(path + ": no skeletons of sensor '" + other + "'; sensors: " + names);
  }
  const auto& ref = in.by_sensor.at(o.ref);
  const auto& oth = in.by_sensor.at(other);
  // The pose the input already implies (a shared frame when it has none).
  Eigen::Isometry3d before = Eigen::Isometry3d::Identity();
  if (in.poses.count(o.ref) && in.poses.count(other)) before = in.poses.at(o.ref).inverse() * in.poses.at(other);

  std::vector<TimedSkeleton> fit_ref = ref, fit_oth = oth, test_ref, test_oth;
  if (o.holdout) {
    auto [fit, test] = split_halves(in.by_sensor, o.ref);
    fit_ref = fit[o.ref], fit_oth = fit[other], test_ref = test[o.ref], test_oth = test[other];
  }
  SkeletonCalibOptions co;
  co.inlier_threshold_m = o.threshold_m;
  co.robust_scale_m = o.robust_scale_m;
  co.max_clock_offset_ns = static_cast<std::int64_t>(o.clock_search_ms * 1e6);
  if (in.poses.count(o.ref) && in.poses.count(other)) co.prior = before;
  PairStep step;
  try {
    step = calibrate_pair_step(fit_ref, fit_oth, before, co);
  } catch (const CalibError& e) {
    throw InputError(path + ": cannot calibrate " + other + " against " + o.ref + ": " + e.what());
  }
  // Never worse than before: judged on the data it was fitted to (the held-out half stays unseen).
  const auto& r = step.fit;
  const bool undecided = step.acceptance.undecided, improved = step.acceptance.improved;
  const Eigen::Isometry3d chosen = step.chosen;
  const std::int64_t chosen_offset = step.chosen_offset_ns;

  nlohmann::json j{{"input", path},
                   {"reference", o.ref},
                   {"other", other},
                   {"frames", {{o.ref, ref.size()}, {other, oth.size()}}},
                   {"reference_from_other", pose_json(r.fit.transform())},
                   {"clock_offset_ms", r.clock_offset_ns / 1e6},
                   {"matched_frames", r.matched},
                   {"mirrored_frames", r.mirrored},
                   {"person_spread_cm", cm(r.person_spread_m)},
                   {"turned_round_inliers", r.turned_inliers},
                   {"ambiguous", r.ambiguous},
                   {"resolved_by_prior", r.resolved_by_prior},
                   {"undecided", undecided},
                   {"joint_pairs", r.pairs},
                   {"inliers", r.inliers},
                   {"rms_residual_cm", cm(r.fit.rms)},
                   {"max_residual_cm", cm(r.fit.max)},
                   {"fit_median_distance_cm",
                    {{"before", json_number(cm(step.acceptance.before_m))}, {"after", json_number(cm(step.acceptance.after_m))}}}};
  nlohmann::json per = nlohmann::json::object();
  for (const auto& jr : r.per_joint) {
    per[skeleton::joint_name(jr.joint)] = {{"pairs", jr.pairs}, {"median_cm", json_number(cm(jr.median_m))}, {"rms_cm", json_number(cm(jr.rms_m))}};
  }
  j["per_joint"] = per;
  if (o.holdout) {
    const auto upper = upper_body();
    const double b = stats::upper_median(joint_distances(test_ref, test_oth, before, 0, upper, 2.0));
    const double a = stats::upper_median(joint_distances(test_ref, test_oth, chosen, chosen_offset, upper, 2.0));
    j["held_out_median_distance_cm"] = {{"before", json_number(cm(b))}, {"after", json_number(cm(a))}};
    if (o.best_rigid) {
      // The floor: the best rigid pose found near the chosen one for the held-out half itself.
      const auto floor = lowest_median_pose(test_ref, test_oth, chosen, chosen_offset, upper, 2.0, o.best_rigid_starts);
      j["held_out_best_rigid_median_cm"] = json_number(cm(floor.median_m));
      j["held_out_best_rigid_starts"] = floor.starts;
    }
    auto& held_out = j["held_out_joints"] = nlohmann::json::array();
    for (auto jid : upper) held_out.push_back(skeleton::joint_name(jid));
  }
  j["verdict"] = undecided ? kUndecided
                : improved ? "calibrated: the fitted pose brings the sensors' skeletons closer than before"
                           : "kept the previous pose: the fit did not bring the skeletons closer on the data it saw";
  j["improved"] = improved;
  if (results != nullptr) {
    skeleton::SensorPose p;
    p.sensor_id = other;
    p.pose = chosen;
    p.method = improved ? "skeleton" : "unchanged";
    p.rms_residual_m = r.fit.rms;
    p.max_residual_m = r.fit.max;
    results->push_back(p);
  }
  return j;
}


}  // namespace skelgraph::calib
