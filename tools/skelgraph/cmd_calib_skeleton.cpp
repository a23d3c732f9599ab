// skelgraph calib skeleton: sensor extrinsics from the skeletons the sensors
// report of the same people (no board), one pair or the whole cell, with
// residuals, a hold-out check, a verdict and a file fusion can use. The
// calibration step and its acceptance policy are calib/calibration_step.hpp.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "cmd_calib.hpp"
#include "skelgraph/calib/board.hpp"
#include "skelgraph/skeleton/json_number.hpp"
#include "skelgraph/skeleton/stats.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/calib/calibration_step.hpp"
#include "skelgraph/calib/inputs.hpp"
#include "skelgraph/calib/sim_check.hpp"
#include "skelgraph/calib/skeleton_calib.hpp"
#include "skelgraph/eval/metrics.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::cli::calib_cmd {

namespace {

// Each sensor's skeletons of one input (calib/inputs.hpp); a bad file is a usage error.
using Input = calib::SkeletonInput;
Input read_input(const std::string& path, const std::string& format, const std::string& on_error) {
  try {
    auto in = calib::read_skeleton_input(path, format, on_error == "skip");
    if (!in.skipped_note.empty()) std::fprintf(stderr, "note: %s\n", in.skipped_note.c_str());
    return in;
  } catch (const calib::InputError& e) {
    throw UsageError(e.what());
  }
}

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
nlohmann::json calibrate_cell_input(const std::string& path, const SkelOptions& o, const Input& in,
                                    std::vector<skeleton::SensorPose>* result) {
  calib::SensorSkeletons fit = in.by_sensor, test;
  if (o.holdout) {
    auto halves = calib::split_halves(in.by_sensor, o.ref);
    fit = std::move(halves.fit), test = std::move(halves.test);
  }
  // The poses the input already implies (a shared frame when it has none).
  calib::SensorPoses before;
  for (const auto& [id, v] : in.by_sensor) {
    before[id] = in.poses.count(o.ref) && in.poses.count(id) ? Eigen::Isometry3d(in.poses.at(o.ref).inverse() * in.poses.at(id))
                                                             : Eigen::Isometry3d::Identity();
  }
  calib::CellCalibOptions co;
  co.pair.inlier_threshold_m = o.threshold_m;
  co.pair.robust_scale_m = o.robust_scale_m;
  co.prior = in.poses;
  calib::CellStep step;
  try {
    step = calib::calibrate_cell_step(fit, o.ref, before, co);
  } catch (const calib::CalibError& e) {
    throw UsageError(path + ": cannot calibrate the cell against " + o.ref + ": " + e.what());
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
      sj["held_out_median_distance_cm"] = {{"before", json_number(cm(calib::cell_median(test, id, before, upper)))},
                                           {"after", json_number(cm(calib::cell_median(test, id, chosen, upper)))}};
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

// One input: fit (on the first half with --holdout), check, and the verdict.
nlohmann::json calibrate_one(const std::string& path, const SkelOptions& o, std::vector<skeleton::SensorPose>* results) {
  Input in = read_input(path, o.format, o.on_error);
  if (o.prior == "shared") {
    for (const auto& [id, v] : in.by_sensor) in.poses[id] = Eigen::Isometry3d::Identity();
  } else if (!o.prior.empty()) {
    in.poses = prior_poses(o.prior);
  }
  std::string names;
  for (const auto& [id, v] : in.by_sensor) names += (names.empty() ? "" : ", ") + id + " (" + std::to_string(v.size()) + ")";
  if (!in.by_sensor.count(o.ref)) throw UsageError(path + ": no skeletons of reference sensor '" + o.ref + "'; sensors: " + names);
  std::string other = o.other;
  if (other.empty()) {
    if (in.by_sensor.size() > 2) return calibrate_cell_input(path, o, in, results);
    for (const auto& [id, v] : in.by_sensor)
      if (id != o.ref) other = id;
    if (other.empty()) throw UsageError(path + ": only the reference sensor has skeletons (" + names + ")");
  } else if (!in.by_sensor.count(other)) {
    throw UsageError(path + ": no skeletons of sensor '" + other + "'; sensors: " + names);
  }
  const auto& ref = in.by_sensor.at(o.ref);
  const auto& oth = in.by_sensor.at(other);
  // The pose the input already implies (a shared frame when it has none).
  Eigen::Isometry3d before = Eigen::Isometry3d::Identity();
  if (in.poses.count(o.ref) && in.poses.count(other)) before = in.poses.at(o.ref).inverse() * in.poses.at(other);

  std::vector<calib::TimedSkeleton> fit_ref = ref, fit_oth = oth, test_ref, test_oth;
  if (o.holdout) {
    auto [fit, test] = calib::split_halves(in.by_sensor, o.ref);
    fit_ref = fit[o.ref], fit_oth = fit[other], test_ref = test[o.ref], test_oth = test[other];
  }
  calib::SkeletonCalibOptions co;
  co.inlier_threshold_m = o.threshold_m;
  co.robust_scale_m = o.robust_scale_m;
  co.max_clock_offset_ns = static_cast<std::int64_t>(o.clock_search_ms * 1e6);
  if (in.poses.count(o.ref) && in.poses.count(other)) co.prior = before;
  calib::PairStep step;
  try {
    step = calib::calibrate_pair_step(fit_ref, fit_oth, before, co);
  } catch (const calib::CalibError& e) {
    throw UsageError(path + ": cannot calibrate " + other + " against " + o.ref + ": " + e.what());
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
    const double b = stats::upper_median(calib::joint_distances(test_ref, test_oth, before, 0, upper, 2.0));
    const double a = stats::upper_median(calib::joint_distances(test_ref, test_oth, chosen, chosen_offset, upper, 2.0));
    j["held_out_median_distance_cm"] = {{"before", json_number(cm(b))}, {"after", json_number(cm(a))}};
    if (o.best_rigid) {
      // The floor: the best rigid pose found near the chosen one for the held-out half itself.
      const auto floor = calib::lowest_median_pose(test_ref, test_oth, chosen, chosen_offset, upper, 2.0, o.best_rigid_starts);
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

}  // namespace

int calib_skeleton(const SkelOptions& o) {
  if (!o.format.empty() && !playback::format_from_name(o.format)) throw UsageError("unknown format " + o.format);
  if (!o.out.empty() && o.inputs.size() != 1) throw UsageError("--out needs exactly one input");
  nlohmann::json all = nlohmann::json::array();
  int failed = 0;
  BadInputs bad;
  for (const auto& path : o.inputs) {
    std::vector<skeleton::SensorPose> poses;
    nlohmann::json j;
    // One bad input does not stop the others; the exit code says one was bad (2).
    if (!bad.guard([&] { j = calibrate_one(path, o, &poses); })) {
      all.push_back({{"input", path}, {"error", bad.messages().back()}});
      continue;
    }
    const bool cell = j.value("mode", "") == "cell";
    if (cell ? j["unplaced"].get<std::size_t>() + j["undecided"].get<std::size_t>() > 0 : j["undecided"].get<bool>())
      ++failed;
    if (!o.out.empty()) {
      // world = the reference sensor's frame, unless --ref-pose places the reference in a world.
      const Eigen::Isometry3d world_from_ref = reference_in_world(o.ref_pose, o.ref);
      calib::CalibFile f;
      f.comment = "written by skelgraph calib skeleton " + path + " --ref " + o.ref;
      skeleton::SensorPose ref;
      ref.sensor_id = o.ref;
      ref.pose = world_from_ref;
      ref.method = o.ref_pose.empty() ? "reference" : "from " + o.ref_pose;
      f.sensors = {ref};
      for (auto p : poses) {
        p.pose = world_from_ref * p.pose;
        f.sensors.push_back(p);
      }
      write_calib(o.out, f);
      j["written"] = o.out;
    }
    if (!o.json && cell) {
      std::printf("%s: the whole cell against %s (%d joint solution rounds)\n", path.c_str(), o.ref.c_str(),
                  j["joint_solution_rounds"].get<int>());
      for (const auto& sj : j["sensors"]) {
        std::printf("  %s: ", sj["sensor"].get<std::string>().c_str());
        if (sj["placed"].get<bool>()) {
          const auto& p = sj["reference_from_sensor"];
          std::string via;
          for (const auto& h : sj["path"]) via += (via.empty() ? "" : " > ") + h.get<std::string>();
          std::printf("rotation %.2f deg, translation [%.3f, %.3f, %.3f] m, via %s; median distance to the others, "
                      "fitted data %s -> %s cm",
                      p["rotation_deg"].get<double>(), p["translation_m"][0].get<double>(), p["translation_m"][1].get<double>(),
                      p["translation_m"][2].get<double>(), via.c_str(), sj["fit_median_distance_cm"]["before"].dump().c_str(),
                      sj["fit_median_distance_cm"]["after"].dump().c_str());
          if (o.holdout)
            std::printf(", held-out %s -> %s cm", sj["held_out_median_distance_cm"]["before"].dump().c_str(),
                        sj["held_out_median_distance_cm"]["after"].dump().c_str());
          std::printf("\n    %s\n", sj["verdict"].get<std::string>().c_str());
        } else {
          std::printf("%s\n", sj["verdict"].get<std::string>().c_str());
        }
      }
      std::printf("  pairs (median distance under the joint solution, frames seen from the back):");
      for (const auto& l : j["links"]) {
        if (l["joint_pairs"].get<std::size_t>() == 0) continue;
        std::printf(" %s-%s %s cm (%zu mirrored);", l["a"].get<std::string>().c_str(), l["b"].get<std::string>().c_str(),
                    l["median_distance_cm"].dump().c_str(), l["mirrored_frames"].get<std::size_t>());
      }
      std::printf("%s\n", o.out.empty() ? "" : ("\n  written to " + o.out).c_str());
    } else if (!o.json) {
      std::printf("%s: %s from %s\n", path.c_str(), j["other"].get<std::string>().c_str(), o.ref.c_str());
      const auto& p = j["reference_from_other"];
      std::printf("  pose: rotation %.2f deg, translation [%.3f, %.3f, %.3f] m, clock offset %.1f ms\n",
                  p["rotation_deg"].get<double>(), p["translation_m"][0].get<double>(), p["translation_m"][1].get<double>(),
                  p["translation_m"][2].get<double>(), j["clock_offset_ms"].get<double>());
      std::printf("  %zu frames matched, %zu of them seen from the back (sides swapped); %zu of %zu joint pairs within %.0f cm, "
                  "RMS %.1f cm, max %.1f cm\n",
                  j["matched_frames"].get<std::size_t>(), j["mirrored_frames"].get<std::size_t>(),
                  j["inliers"].get<std::size_t>(), j["joint_pairs"].get<std::size_t>(), o.threshold_m * 100,
                  j["rms_residual_cm"].get<double>(), j["max_residual_cm"].get<double>());
      std::printf("  per joint (median / RMS cm):");
      for (const auto& [name, v] : j["per_joint"].items()) {
        std::printf(" %s %s/%s", name.c_str(), v["median_cm"].dump().c_str(), v["rms_cm"].dump().c_str());
      }
      std::printf("\n  median joint distance between the sensors, fitted data: %s -> %s cm\n",
                  j["fit_median_distance_cm"]["before"].dump().c_str(), j["fit_median_distance_cm"]["after"].dump().c_str());
      if (o.holdout) {
        std::printf("  held-out second half: %s -> %s cm\n", j["held_out_median_distance_cm"]["before"].dump().c_str(),
                    j["held_out_median_distance_cm"]["after"].dump().c_str());
        if (o.best_rigid)
          std::printf("  best rigid pose for the held-out half itself: %s cm (what no calibration can beat there)\n",
                      j["held_out_best_rigid_median_cm"].dump().c_str());
      }
      std::printf("  %s%s\n", j["verdict"].get<std::string>().c_str(),
                  o.out.empty() ? "" : ("; written to " + o.out).c_str());
    }
    all.push_back(std::move(j));
  }
  if (o.json) std::printf("%s\n", all.dump(2).c_str());
  return bad.exit_code(failed > 0 ? 1 : 0, o.inputs.size());
}

}  // namespace skelgraph::cli::calib_cmd
