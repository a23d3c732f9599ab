// skelgraph calib skeleton|intrinsics|board: sensor extrinsics from the
// skeletons two sensors report of the same people (no board), camera
// intrinsics from checkerboard images, and extrinsics from a checkerboard both
// sensors see (colour + depth); each with residuals, a verdict and a file
// (YAML) fusion can use. No DDS.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli.hpp"
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

namespace skelgraph::cli {

namespace {

struct SkelOptions {
  std::vector<std::string> inputs;
  std::string format;  // empty: MCAP recordings
  std::string ref, other, out, ref_pose, prior;
  std::string on_error = "stop";  // a bad line in a data-set file: stop (the input is bad) or skip it
  double threshold_m = 0.12, clock_search_ms = 0, robust_scale_m = 0.05;
  bool holdout = false, json = false, best_rigid = false;
  int best_rigid_starts = 1;
};

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

nlohmann::json pose_json(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  return {{"translation_m", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
          {"rotation_deg", calib::rotation_angle_deg(T.rotation())}};
}

double cm(double m) { return std::isfinite(m) ? std::round(m * 1000.0) / 10.0 : m; }

// The reference sensor's pose in the world: from a calibration file, or the
// identity (the reference's frame is the world) without one.
Eigen::Isometry3d reference_in_world(const std::string& file, const std::string& ref) {
  if (file.empty()) return Eigen::Isometry3d::Identity();
  try {
    for (const auto& p : calib::read_calib_file(file).sensors) {
      if (p.sensor_id == ref) return p.pose;
    }
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
  throw UsageError(file + ": has no pose of the reference sensor '" + ref + "'");
}

// A calibration file's poses (world_from_sensor): --prior.
std::map<std::string, Eigen::Isometry3d> prior_poses(const std::string& file) {
  std::map<std::string, Eigen::Isometry3d> poses;
  try {
    for (const auto& p : calib::read_calib_file(file).sensors) poses[p.sensor_id] = p.pose;
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
  return poses;
}

// What a result says when the skeletons could not tell on which side of the person a sensor is.
const char* const kUndecided =
    "ambiguous: the person hardly moved about (turned on the spot?), so the skeletons cannot tell on which side of "
    "them the sensor is, and nothing decided: kept the previous pose (the fit's guess, the side where both sensors "
    "see the front more often, is in the JSON). Walk a loop facing where you go, or give the rough layout with --prior";

void write_calib(const std::string& out, const calib::CalibFile& f) {
  try {
    calib::write_calib_file(out, f);
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
}

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

// --- The simulated cell: calibrated from its skeletons, against its truth ---

struct SimCalibOptions {
  std::vector<std::string> layouts{"ring:3", "ring:4", "ring:6", "corners:4"};
  std::vector<std::string> scenarios{"walk", "360"};
  std::vector<int> seeds{1, 2, 3};
  double seconds = 60;
  std::vector<std::string> params;
  double target_deg = 1.0, target_cm = 2.0;
  bool json = false, floor = false;
};

nlohmann::json calib_sim_run(const SimCalibOptions& o, const std::string& layout, const std::string& scenario, int seed) {
  const auto colon = layout.find(':');
  if (colon == std::string::npos) throw UsageError("--layouts: '" + layout + "' is not LAYOUT:SENSORS, e.g. ring:3");
  const std::string name = layout.substr(0, colon), count = layout.substr(colon + 1);
  const sim::SimConfig cfg = sim_config(o.params, "calib sim",
                                        {{"layout", name, "--layouts"},
                                         {"sensor_count", count, "--layouts"},
                                         {"scenario", scenario, "--scenarios"},
                                         {"seed", std::to_string(seed), "--seeds"},
                                         {"repeats", "1000", "calib sim"}});
  const auto check = calib::check_cell_calibration(cfg, o.seconds, o.floor);
  nlohmann::json run{{"layout", name}, {"sensor_count", cfg.sensors.size()}, {"scenario", scenario}, {"seed", seed},
                     {"seconds", o.seconds}, {"reference", check.reference}};
  if (!check.error.empty()) {
    run["error"] = check.error;
    run["within_target"] = false;
    return run;
  }
  auto& sensors = run["sensors"] = nlohmann::json::array();
  for (const auto& s : check.sensors) {
    nlohmann::json j{{"sensor", s.sensor}, {"frames", s.frames}, {"placed", s.placed}};
    if (s.placed) {
      j["path"] = s.fit.path;
      j["ambiguous"] = s.fit.ambiguous;
      j["rotation_error_deg"] = s.error.deg;
      j["translation_error_cm"] = s.error.cm;
      j["median_distance_cm"] = json_number(cm(s.fit.median_m));
      if (s.pair && s.pair->solved) {
        const auto& f = s.pair->fit;
        j["pair_alone"] = {{"rotation_error_deg", s.pair_error.deg}, {"translation_error_cm", s.pair_error.cm},
                           {"mirrored_frames", f.mirrored}, {"matched_frames", f.matched}, {"ambiguous", f.ambiguous},
                           {"inliers", f.inliers}, {"turned_inliers", f.turned_inliers}};
      } else if (s.pair) {
        j["pair_alone"] = {{"error", s.pair->error}};
      }
      if (s.floor) {
        // The floor: how far the pose the skeletons themselves favour is from the truth, which no calibration from them can undo.
        j["floor"] = {{"rotation_error_deg", s.floor_error.deg}, {"translation_error_cm", s.floor_error.cm},
                      {"median_cm", json_number(cm(s.floor->median_m))},
                      {"median_at_truth_cm", json_number(cm(s.floor->start_median_m))}};
      }
    }
    sensors.push_back(j);
  }
  run["max_rotation_error_deg"] = check.worst.deg;
  run["max_translation_error_cm"] = check.worst.cm;
  run["within_target"] = check.within(o.target_deg, o.target_cm);
  return run;
}

int calib_sim(const SimCalibOptions& o) {
  nlohmann::json runs = nlohmann::json::array();
  const std::size_t total = o.layouts.size() * o.scenarios.size() * o.seeds.size();
  Progress progress;  // on stderr, with --json too: a run takes seconds
  std::size_t within = 0;
  double worst_deg = 0, worst_cm = 0;
  if (!o.json) {
    std::printf("Every sensor calibrated from %.0f s of skeletons, the whole cell at once, against the simulator's truth "
                "(target: within %.1f deg and %.1f cm)\n",
                o.seconds, o.target_deg, o.target_cm);
  }
  for (const auto& layout : o.layouts) {
    for (const auto& scenario : o.scenarios) {
      for (const int seed : o.seeds) {
        progress("calibrating " + layout + " " + scenario + " seed " + std::to_string(seed) + " (" +
                 std::to_string(runs.size() + 1) + " of " + std::to_string(total) + ")");
        auto run = calib_sim_run(o, layout, scenario, seed);
        progress.done(false);
        within += run["within_target"].get<bool>() ? 1 : 0;
        if (run.contains("max_rotation_error_deg")) {
          worst_deg = std::max(worst_deg, run["max_rotation_error_deg"].get<double>());
          worst_cm = std::max(worst_cm, run["max_translation_error_cm"].get<double>());
        }
        if (!o.json) {
          std::printf("%-10s %-5s seed %d: ", layout.c_str(), scenario.c_str(), seed);
          if (run.contains("error")) {
            std::printf("FAILED: %s\n", run["error"].get<std::string>().c_str());
          } else {
            for (const auto& s : run["sensors"]) {
              if (!s["placed"].get<bool>()) std::printf(" %s not placed;", s["sensor"].get<std::string>().c_str());
              else std::printf(" %s %.2f deg %.1f cm%s;", s["sensor"].get<std::string>().c_str(),
                               s["rotation_error_deg"].get<double>(), s["translation_error_cm"].get<double>(),
                               s["ambiguous"].get<bool>() ? " (ambiguous)" : "");
            }
            std::printf(" %s\n", run["within_target"].get<bool>() ? "ok" : "OUTSIDE");
          }
        }
        runs.push_back(std::move(run));
      }
    }
  }
  const nlohmann::json summary{{"runs", runs.size()}, {"within_target", within}, {"target_deg", o.target_deg},
                               {"target_cm", o.target_cm}, {"max_rotation_error_deg", worst_deg},
                               {"max_translation_error_cm", worst_cm}};
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"summary", summary}, {"runs", runs}}.dump(2).c_str());
  } else {
    std::printf("%zu of %zu runs with every sensor within target; worst %.2f deg, %.1f cm\n", within, runs.size(), worst_deg,
                worst_cm);
  }
  return within == runs.size() ? 0 : 1;
}

// --- Checkerboards ---

struct BoardOptions {
  std::vector<std::string> images;  // intrinsics
  std::string ref_dir, other_dir, ref = "sensor1", other = "sensor2";
  std::string size = "9x6";
  double square_m = 0.08;
  std::string ref_intrinsics, other_intrinsics, ref_pose, out;
  std::string world_markers;  // one directory: its sensor to the motion-capture frame
  bool json = false;
};

calib::Board board_of(const BoardOptions& o) {
  try {
    return calib::Board::parse(o.size, o.square_m);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
}

int calib_intrinsics(const BoardOptions& o) {
  const auto board = board_of(o);
  std::vector<calib::Corners> found;
  std::vector<std::string> missed;
  int width = 0, height = 0;
  Progress progress(!o.json);
  for (std::size_t i = 0; i < o.images.size(); ++i) {
    calib::GreyImage grey;
    try {
      grey = calib::read_grey_image(o.images[i]);
    } catch (const calib::CalibError& e) {
      throw UsageError(e.what());
    }
    if (width == 0) width = grey.width, height = grey.height;
    if (grey.width != width || grey.height != height) {
      throw UsageError(o.images[i] + ": " + std::to_string(grey.width) + "x" + std::to_string(grey.height) +
                       ", the other images are " + std::to_string(width) + "x" + std::to_string(height));
    }
    if (auto c = calib::find_corners(grey, board)) found.push_back(std::move(*c));
    else missed.push_back(o.images[i]);
    progress("looking for the board: " + std::to_string(i + 1) + " of " + std::to_string(o.images.size()) + " images",
             i + 1 == o.images.size());
  }
  if (found.size() < 3) {
    throw UsageError("the " + o.size + " board (inner corners, columns x rows) was found in " + std::to_string(found.size()) +
                     " of " + std::to_string(o.images.size()) +
                     " images; intrinsics need it in 3 or more (is --board right? a 10x7-square board has 9x6 inner corners)");
  }
  calib::IntrinsicsResult r;
  try {
    r = calib::calibrate_intrinsics(found, board, width, height);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
  const auto& k = r.intrinsics;
  const bool good = r.rms_reprojection_px < 1.0;
  nlohmann::json j{{"images", o.images.size()}, {"views_used", r.views}, {"board_not_found", missed},
                   {"width", k.width}, {"height", k.height}, {"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy},
                   {"distortion", k.distortion}, {"rms_reprojection_px", r.rms_reprojection_px},
                   {"verdict", good ? "good: reprojection RMS below 1 px" : "poor: reprojection RMS of 1 px or more (blurred images, a bent board, the wrong --board?)"}};
  if (!o.out.empty()) {
    try {
      calib::write_intrinsics_file(o.out, k, r.rms_reprojection_px, r.views,
                                   "written by skelgraph calib intrinsics (" + std::to_string(r.views) + " views, board " + o.size + ")");
    } catch (const calib::CalibFileError& e) {
      throw UsageError(e.what());
    }
    j["written"] = o.out;
  }
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("board found in %zu of %zu images\nfx %.2f fy %.2f cx %.2f cy %.2f (%dx%d), reprojection RMS %.3f px: %s%s\n",
                r.views, o.images.size(), k.fx, k.fy, k.cx, k.cy, k.width, k.height, r.rms_reprojection_px,
                j["verdict"].get<std::string>().c_str(), o.out.empty() ? "" : ("; written to " + o.out).c_str());
  }
  return good ? 0 : 1;
}

calib::Intrinsics intrinsics_for(const std::string& dir, const std::string& given) {
  const std::string path = given.empty() ? (std::filesystem::path(dir) / "intrinsics.yaml").string() : given;
  if (!std::filesystem::exists(path)) {
    throw UsageError(path + ": no intrinsics (run `skelgraph calib intrinsics " + dir + "/*_color.png --out " + path +
                     "`, or give them with --ref-intrinsics/--other-intrinsics)");
  }
  try {
    return calib::read_intrinsics_file(path);
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
}

// The library's board views, an unreadable file being a usage error (the user named it).
std::vector<std::string> view_names(const std::string& dir) {
  try {
    return calib::board_view_names(dir);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
}
std::optional<std::vector<Eigen::Vector3d>> lift_view(const std::string& dir, const std::string& name,
                                                      const calib::Board& board, const calib::Intrinsics& k,
                                                      std::string* why) {
  try {
    return calib::lift_board_view(dir, name, board, k, why);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
}

int calib_board(const BoardOptions& o) {
  const auto board = board_of(o);
  // Two directories: the other sensor against the reference. One directory
  // and --world-markers: that sensor against the motion-capture frame, the
  // board's corners placed in it by its markers.
  const bool world = !o.world_markers.empty();
  if (world == !o.other_dir.empty()) {
    throw UsageError("give either two view directories (sensor to sensor) or one with --world-markers (sensor to world)");
  }
  calib::BoardMarkers markers;
  if (world) {
    try {
      markers = calib::read_board_markers(o.world_markers);
    } catch (const calib::CalibFileError& e) {
      throw UsageError(e.what());
    }
  }
  const std::vector<std::string> dirs = world ? std::vector<std::string>{o.ref_dir} : std::vector<std::string>{o.ref_dir, o.other_dir};
  std::vector<calib::Intrinsics> ks{intrinsics_for(o.ref_dir, o.ref_intrinsics)};
  if (!world) ks.push_back(intrinsics_for(o.other_dir, o.other_intrinsics));
  std::vector<std::vector<Eigen::Vector3d>> ref, other;
  std::vector<std::string> used, skipped;
  std::vector<double> marker_rms;
  const auto names = view_names(o.ref_dir);
  if (names.empty()) throw UsageError(o.ref_dir + ": no NAME_color.png views");
  Progress progress(!o.json);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& n = names[i];
    std::vector<std::vector<Eigen::Vector3d>> lifted(dirs.size());
    bool ok = true;
    if (world && !markers.in_world.count(n)) {
      skipped.push_back(n + ": no markers for this view in " + o.world_markers);
      ok = false;
    }
    for (std::size_t c = 0; c < dirs.size() && ok; ++c) {
      std::string why;
      auto points = lift_view(dirs[c], n, board, ks[c], &why);
      if (!points) {
        ok = false;
        skipped.push_back(why);
        break;
      }
      lifted[c] = std::move(*points);
    }
    progress("views: " + std::to_string(i + 1) + " of " + std::to_string(names.size()) + " read", i + 1 == names.size());
    if (!ok) continue;
    if (world) {
      // The board in the world from its markers, then its corners there.
      calib::Alignment wb;
      try {
        wb = calib::align(markers.in_board, markers.in_world.at(n));
      } catch (const calib::CalibError& e) {
        throw UsageError(o.world_markers + ": view " + n + ": " + e.what());
      }
      marker_rms.push_back(wb.rms);
      std::vector<Eigen::Vector3d> w;
      for (const auto& p : board.object_points()) w.push_back(wb.apply(p));
      ref.push_back(std::move(w));
      other.push_back(std::move(lifted[0]));
    } else {
      ref.push_back(std::move(lifted[0]));
      other.push_back(std::move(lifted[1]));
    }
    used.push_back(n);
  }
  if (ref.size() < 3) throw UsageError("the board was usable in only " + std::to_string(ref.size()) + " views (need 3): " + (skipped.empty() ? "" : skipped.front()));
  calib::RansacResult r;
  try {
    r = calib::pose_from_views(ref, other);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
  // Camera frames (x right, y down) -> skelgraph sensor frames (x left, y up);
  // in world mode the reference side is the world itself.
  const Eigen::Matrix3d S = calib::sensor_from_camera();
  const Eigen::Matrix3d L = world ? Eigen::Matrix3d::Identity() : S;
  Eigen::Isometry3d ref_from_other = Eigen::Isometry3d::Identity();
  ref_from_other.linear() = L * r.fit.R * S.transpose();
  ref_from_other.translation() = L * r.fit.t;
  const std::size_t corners = ref.size() * ref.front().size();
  const bool good = r.fit.rms < 0.01 && r.inliers.size() * 10 >= corners * 9;
  const std::string ref_name = world ? "world" : o.ref, other_name = world ? o.ref : o.other;
  nlohmann::json j{{"reference", ref_name}, {"other", other_name}, {"views", names.size()}, {"views_used", used.size()},
                   {"skipped", skipped}, {"reference_from_other", pose_json(ref_from_other)},
                   {"corners", corners}, {"inliers", r.inliers.size()},
                   {"rms_residual_cm", cm(r.fit.rms)}, {"max_residual_cm", cm(r.fit.max)},
                   {"verdict", good ? std::string("good: corners agree within 1 cm RMS")
                                    : std::string("poor: corners disagree (RMS 1 cm or more, or over 10 % outliers): check the "
                                                  "intrinsics and that the depth is registered") +
                                          (world ? ", and that --square and the marker file describe this board" : "")}};
  if (world) {
    double worst = 0;
    for (double m : marker_rms) worst = std::max(worst, m);
    j["marker_fit_rms_cm_worst"] = cm(worst);
  }
  if (!o.out.empty() && world) {
    calib::CalibFile f;
    f.comment = "written by skelgraph calib board " + o.ref_dir + " --world-markers " + o.world_markers;
    skeleton::SensorPose p;
    p.sensor_id = o.ref;
    p.pose = ref_from_other;
    p.method = "checkerboard";
    p.rms_residual_m = r.fit.rms;
    p.max_residual_m = r.fit.max;
    f.sensors = {p};
    write_calib(o.out, f);
    j["written"] = o.out;
  } else if (!o.out.empty()) {
    const Eigen::Isometry3d world_from_ref = reference_in_world(o.ref_pose, o.ref);
    const std::string ref_method = o.ref_pose.empty() ? "reference" : "from " + o.ref_pose;
    calib::CalibFile f;
    f.comment = "written by skelgraph calib board " + o.ref_dir + " " + o.other_dir;
    skeleton::SensorPose pr, po;
    pr.sensor_id = o.ref;
    pr.pose = world_from_ref;
    pr.method = ref_method;
    po.sensor_id = o.other;
    po.pose = world_from_ref * ref_from_other;
    po.method = "checkerboard";
    po.rms_residual_m = r.fit.rms;
    po.max_residual_m = r.fit.max;
    f.sensors = {pr, po};
    write_calib(o.out, f);
    j["written"] = o.out;
  }
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    const auto& p = j["reference_from_other"];
    std::printf("%s from %s: %zu of %zu views used; rotation %.2f deg, translation [%.3f, %.3f, %.3f] m\n"
                "%zu of %zu corners within 2 cm, RMS %.2f cm, max %.2f cm: %s%s\n",
                other_name.c_str(), ref_name.c_str(), used.size(), names.size(), p["rotation_deg"].get<double>(),
                p["translation_m"][0].get<double>(), p["translation_m"][1].get<double>(), p["translation_m"][2].get<double>(),
                r.inliers.size(), corners, cm(r.fit.rms), cm(r.fit.max), j["verdict"].get<std::string>().c_str(),
                o.out.empty() ? "" : ("; written to " + o.out).c_str());
    for (const auto& s : skipped) std::printf("  skipped %s\n", s.c_str());
  }
  return good ? 0 : 1;
}


struct RobotOptions {
  std::vector<std::string> dirs;  // board on the tool: one directory of views per sensor
  std::string tool_poses;         // ... and what the robot reported for each view
  std::string hand_recording;     // hand at the tool: a recording of robot/state and skeleton/raw
  std::string hand = "either";
  std::string intrinsics;         // for every directory (default DIR/intrinsics.yaml)
  std::string base = "0,0,1.5,180";
  std::string size = "9x6";
  double square_m = 0.08, hold_s = 1.0, inlier_cm = 8.0;
  std::string truth, out, cell;
  bool json = false;
};

// The hand at the tool (calib/inputs.hpp); a bad recording is a usage error.
calib::HandInput read_hand_input(const std::string& path, const std::vector<skeleton::JointId>& joints) {
  try {
    return calib::read_hand_input(path, joints);
  } catch (const calib::InputError& e) {
    throw UsageError(e.what());
  }
}

int calib_robot(const RobotOptions& o) {
  const bool hand_mode = !o.hand_recording.empty();
  if (hand_mode == !o.tool_poses.empty()) {
    throw UsageError("give either --tool-poses with one view directory per sensor (a board on the tool), or --hand "
                     "RECORDING (a hand held at the tool)");
  }
  if (!hand_mode && o.dirs.empty()) throw UsageError("--tool-poses needs one or more view directories (one per sensor, named by its id)");
  if (hand_mode && !o.dirs.empty()) throw UsageError("--hand takes no view directories");
  Eigen::Isometry3d world_from_base;
  try {
    world_from_base = robot::parse_base(o.base);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--base: ") + e.what());
  }
  std::map<std::string, Eigen::Isometry3d> truth;
  if (!o.truth.empty()) truth = prior_poses(o.truth);

  struct Result {
    std::string sensor;
    calib::RobotFit fit;
    std::vector<std::string> skipped;
    std::size_t offered = 0;  // views (board) or holds (hand)
    std::size_t places = 0, places_agreeing = 0;  // hand: where the tool held still, and where a hand agreed
  };
  std::vector<Result> results;
  std::vector<std::string> failed;  // sensors without a fit, with the reason
  std::vector<std::string> cell_sensors;  // --cell: the sensors fitted together
  if (hand_mode) {
    // Either hand by default: a tracker that sees the person's back swaps left and right,
    // and the hand not at the tool is an outlier RANSAC leaves out.
    std::vector<skeleton::JointId> joints;
    if (o.hand != "left") joints.push_back(skeleton::JointId::RightHand);
    if (o.hand != "right") joints.push_back(skeleton::JointId::LeftHand);
    const auto in = read_hand_input(o.hand_recording, joints);
    calib::HoldOptions ho;
    ho.hold_s = o.hold_s;
    // --cell: the sensors already calibrated to each other; every sensor's
    // holds in that frame, one fit for the whole cell (the sensors' hand
    // errors differ by view and partly cancel).
    std::map<std::string, Eigen::Isometry3d> cell;
    if (!o.cell.empty()) cell = prior_poses(o.cell);
    std::map<std::string, std::vector<calib::Hold>> by_sensor;
    for (const auto& [sensor, people] : in.hands) {
      auto& holds = by_sensor[sensor];
      for (const auto& [id, pts] : people) {
        const auto h = calib::find_holds(in.tool, pts, ho);
        holds.insert(holds.end(), h.begin(), h.end());
      }
      // The tool's positions are in the world the robot reports in: to its base.
      for (auto& h : holds) h.tool = world_from_base.inverse() * h.tool;
    }
    if (!cell.empty()) {
      std::vector<calib::Hold> pooled;
      std::vector<std::string> in_cell;
      for (auto& [sensor, holds] : by_sensor) {
        const auto c = cell.find(sensor);
        if (c == cell.end()) {
          failed.push_back(sensor + ": not in " + o.cell);
          continue;
        }
        for (auto h : holds) {
          h.hand = c->second * h.hand;
          pooled.push_back(h);
        }
        in_cell.push_back(sensor);
      }
      by_sensor.clear();
      by_sensor["cell"] = pooled;
      cell_sensors = in_cell;
    }
    for (const auto& [sensor, holds] : by_sensor) {
      // The places the tool held still at (both hands may pair with one).
      const auto places = [&](const std::vector<std::size_t>& which) {
        std::vector<Eigen::Vector3d> out;
        for (std::size_t i : which) {
          if (std::none_of(out.begin(), out.end(), [&](const Eigen::Vector3d& p) { return (p - holds[i].tool).norm() < ho.min_gap_m; })) {
            out.push_back(holds[i].tool);
          }
        }
        return out.size();
      };
      try {
        Result r{sensor, calib::fit_hand_at_tool(holds, o.inlier_cm / 100.0), {}, holds.size()};
        std::vector<std::size_t> all(holds.size());
        for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
        r.places = places(all);
        r.places_agreeing = places(r.fit.ransac.inliers);
        if (sensor == "cell" && !cell.empty()) {  // base_from_cell: each sensor through its pose in the cell
          for (const auto& s : cell_sensors) {
            Result rs = r;
            rs.sensor = s;
            rs.fit.base_from_sensor = r.fit.base_from_sensor * cell.at(s);
            results.push_back(std::move(rs));
          }
        } else {
          results.push_back(std::move(r));
        }
      } catch (const calib::CalibError& e) {
        failed.push_back(sensor + ": " + e.what());
      }
    }
  } else {
    calib::ToolPoses poses;
    try {
      poses = calib::read_tool_poses(o.tool_poses);
    } catch (const calib::CalibFileError& e) {
      throw UsageError(e.what());
    }
    calib::Board board;
    try {
      board = calib::Board::parse(o.size, o.square_m);
    } catch (const calib::CalibError& e) {
      throw UsageError(e.what());
    }
    Progress progress(!o.json);
    for (const auto& dir : o.dirs) {
      const std::string sensor = std::filesystem::path(dir).filename().string();
      const auto k = intrinsics_for(dir, o.intrinsics);
      std::vector<std::vector<Eigen::Vector3d>> corners;
      std::vector<Eigen::Isometry3d> base_from_board;
      std::vector<std::string> skipped;
      const auto names = view_names(dir);
      for (std::size_t i = 0; i < names.size(); ++i) {
        const auto& n = names[i];
        const auto pose = poses.base_from_tool.find(n);
        std::string why;
        if (pose == poses.base_from_tool.end()) {
          skipped.push_back(n + ": no tool pose for this view in " + o.tool_poses);
        } else if (auto pts = lift_view(dir, n, board, k, &why)) {
          corners.push_back(std::move(*pts));
          base_from_board.push_back(pose->second * poses.tool_from_board);
        } else {
          skipped.push_back(why);
        }
        progress(sensor + ": " + std::to_string(i + 1) + " of " + std::to_string(names.size()) + " views read", i + 1 == names.size());
      }
      try {
        results.push_back({sensor, calib::fit_board_on_tool(corners, base_from_board, board.object_points()), skipped, names.size()});
      } catch (const calib::CalibError& e) {
        failed.push_back(sensor + ": " + e.what() + (skipped.empty() ? "" : " (" + skipped.front() + ")"));
      }
    }
  }

  // Verdicts: the board's corners agree within 1 cm RMS with few outliers; a
  // hand (a joint a few cm from the touch, and a tracker's noise) within 4 cm.
  const double good_rms_m = hand_mode ? 0.04 : 0.01;
  nlohmann::json sensors = nlohmann::json::array();
  calib::CalibFile file;
  file.comment = std::string("written by skelgraph calib robot ") +
                 (hand_mode ? "--hand " + o.hand_recording : "--tool-poses " + o.tool_poses) + " --base " + o.base;
  bool all_good = failed.empty() && !results.empty();
  for (const auto& r : results) {
    const auto& f = r.fit.ransac.fit;
    const bool good = f.rms < good_rms_m && (hand_mode ? r.places_agreeing * 10 >= r.places * 8
                                                       : r.fit.ransac.inliers.size() * 10 >= r.fit.points * 8);
    all_good = all_good && good;
    const Eigen::Isometry3d world_from_sensor = world_from_base * r.fit.base_from_sensor;
    nlohmann::json j{{"sensor", r.sensor}, {hand_mode ? "holds" : "views", r.offered}, {"used", r.fit.views},
                     {"points", r.fit.points}, {"inliers", r.fit.ransac.inliers.size()},
                     {"rms_residual_cm", cm(f.rms)}, {"max_residual_cm", cm(f.max)},
                     {"base_from_sensor", pose_json(r.fit.base_from_sensor)}, {"world_from_sensor", pose_json(world_from_sensor)},
                     {"verdict", good ? std::string(hand_mode ? "good: the hand agrees with the tool within 4 cm RMS"
                                                              : "good: corners agree within 1 cm RMS")
                                      : std::string(hand_mode ? "poor: the hand and the tool disagree (4 cm RMS or more, or at over 20 % of the places): "
                                                                "hold the hand on the tool, still, at more places around the workspace"
                                                              : "poor: corners disagree (1 cm RMS or more, or over 20 % outliers): check "
                                                                "the intrinsics, the board's mount on the tool and --board/--square")}};
    if (!r.skipped.empty()) j["skipped"] = r.skipped;
    if (hand_mode) {
      j["places"] = r.places;
      j["places_agreeing"] = r.places_agreeing;
    }
    if (const auto t = truth.find(r.sensor); t != truth.end()) {
      const auto e = calib::pose_error(world_from_sensor, t->second);
      j["error_deg"] = e.deg;
      j["error_cm"] = e.cm;
    }
    sensors.push_back(j);
    skeleton::SensorPose p;
    p.sensor_id = r.sensor;
    p.pose = world_from_sensor;
    p.method = hand_mode ? "robot_hand" : "robot_board";
    p.rms_residual_m = f.rms;
    p.max_residual_m = f.max;
    file.sensors.push_back(p);
  }
  nlohmann::json out{{"method", hand_mode ? "hand at the tool" : "board on the tool"}, {"base", o.base},
                     {"sensors", sensors}, {"failed", failed}};
  if (!o.truth.empty()) {
    double worst_deg = 0, worst_cm = 0;
    for (const auto& s : sensors) {
      if (!s.contains("error_deg")) continue;
      worst_deg = std::max(worst_deg, s["error_deg"].get<double>());
      worst_cm = std::max(worst_cm, s["error_cm"].get<double>());
    }
    out["worst_error_deg"] = worst_deg;
    out["worst_error_cm"] = worst_cm;
  }
  if (!o.out.empty() && !file.sensors.empty()) {
    write_calib(o.out, file);
    out["written"] = o.out;
  }
  if (o.json) {
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    for (const auto& s : sensors) {
      const auto& p = s["world_from_sensor"];
      const std::string used = hand_mode ? std::to_string(s["holds"].get<std::size_t>()) + " holds at " +
                                               std::to_string(s["places"].get<std::size_t>()) + " places, a hand agreeing at " +
                                               std::to_string(s["places_agreeing"].get<std::size_t>())
                                         : std::to_string(s["used"].get<std::size_t>()) + " of " +
                                               std::to_string(s["views"].get<std::size_t>()) + " views used, " +
                                               std::to_string(s["inliers"].get<std::size_t>()) + " of " +
                                               std::to_string(s["points"].get<std::size_t>()) + " corners inliers";
      std::printf("%s: %s, RMS %.2f cm, max %.2f cm; in the world: rotation %.2f deg, translation [%.3f, %.3f, %.3f] m%s: %s\n",
                  s["sensor"].get<std::string>().c_str(), used.c_str(), s["rms_residual_cm"].get<double>(),
                  s["max_residual_cm"].get<double>(), p["rotation_deg"].get<double>(), p["translation_m"][0].get<double>(),
                  p["translation_m"][1].get<double>(), p["translation_m"][2].get<double>(),
                  s.contains("error_deg") ? (" (off the truth by " + std::to_string(s["error_deg"].get<double>()).substr(0, 5) +
                                             " deg, " + std::to_string(s["error_cm"].get<double>()).substr(0, 5) + " cm)").c_str()
                                          : "",
                  s["verdict"].get<std::string>().c_str());
    }
    for (const auto& f : failed) std::printf("no pose for %s\n", f.c_str());
    if (out.contains("written")) std::printf("written to %s\n", o.out.c_str());
  }
  return all_good ? 0 : 1;
}

}  // namespace

void add_calib_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* cal = app.add_subcommand("calib", "Sensor calibration");
  cal->require_subcommand(1);
  auto o = std::make_shared<SkelOptions>();
  auto* s = cal->add_subcommand(
      "skeleton",
      "Extrinsics from the person's own skeleton: sensors' skeletons of the same people at the same time (walk "
      "around in front of them for 30 s or more); views of the back are used with their sides swapped, other people "
      "rejected. Without --other and with more than one other sensor: every sensor of the cell at once, one file");
  s->add_option("inputs", o->inputs, "MCAP recordings (skelgraph/skeleton/raw), or data-set files with --format")
      ->required()
      ->check(CLI::ExistingFile);
  s->add_option("--format", o->format, "the inputs are data-set files of this format")
      ->check(CLI::IsMember(playback::format_names()));
  s->add_option("--on-error", o->on_error, "a bad line in a data-set file: stop (default: the input is bad, reported, the "
                                           "others still calibrated, exit 2 at the end) or skip the line")
      ->check(CLI::IsMember({"stop", "skip"}))
      ->needs("--format");
  s->add_option("--ref", o->ref, "reference sensor id (its frame is the result's frame)")->required();
  s->add_option("--other", o->other, "the one sensor to calibrate against the reference (default: the only other one, or "
                                     "with several: all of them, jointly)");
  s->add_option("--prior", o->prior,
                "a calibration file with the sensors' rough poses (a previous calibration, a measured layout), or "
                "'shared' when the input's skeletons already share a rough frame (data sets mapped by their recording "
                "app): the previous poses (instead of the recording's), and what decides when the skeletons cannot "
                "tell on which side of the person a sensor is")
      ->check(CLI::ExistingFile | CLI::IsMember({"shared"}));
  s->add_option("--threshold-m", o->threshold_m, "a joint pair agrees within this under a good pose")->check(kPositive);
  s->add_option("--robust-scale-m", o->robust_scale_m, "scale of the Cauchy weights in the refits, 1 / (1 + (r / this)^2) (default 0.05; 0: plain least squares)")
      ->check(CLI::NonNegativeNumber);
  s->add_option("--clock-search-ms", o->clock_search_ms,
                "search the other sensor's clock offset within +-this (0: the clocks agree)")
      ->check(kNonNegative);
  auto* holdout = s->add_flag("--holdout", o->holdout, "fit on the first half of each input, report distances on the second half");
  auto* best_rigid = s->add_flag("--best-rigid", o->best_rigid,
              "with --holdout: also search for the rigid pose with the lowest median on the second half itself (a "
              "local search from the fit; 2.8 s more for the 13 KinectMultiTrack files): the floor no calibration can beat there")
      ->needs(holdout);
  s->add_option("--best-rigid-starts", o->best_rigid_starts,
                "with --best-rigid: search from the fit and from this many - 1 poses around it (up to 10 degrees and 30 cm "
                "off, fixed seed), keeping the lowest (default 1)")
      ->check(CLI::Range(1, 1000))
      ->needs(best_rigid);
  s->add_option("--out", o->out, "write a calibration file (YAML; e.g. bringup/calib/NAME.yaml)");
  s->add_option("--ref-pose", o->ref_pose, "a calibration file with the reference sensor's pose in the world (default: the reference is the world)")
      ->check(CLI::ExistingFile);
  s->add_flag("--json", o->json, "machine-readable results, one object per input");
  s->callback([o, &run] { run = [o] { return calib_skeleton(*o); }; });

  auto so = std::make_shared<SimCalibOptions>();
  auto* sc = cal->add_subcommand("sim",
                                 "Calibrate the simulated cell from its skeletons (every sensor, the whole cell at once) and "
                                 "compare each pose with the simulator's truth; exit 1 when a run misses the target");
  sc->add_option("--layouts", so->layouts, "LAYOUT:SENSORS list (layouts: quarters, ring, one_side, corners; default "
                                           "ring:3,ring:4,ring:6,corners:4)")
      ->delimiter(',');
  sc->add_option("--scenarios", so->scenarios, "simulator scenarios (default walk,360)")->delimiter(',');
  sc->add_option("--seeds", so->seeds, "seeds (default 1,2,3)")->delimiter(',');
  sc->add_option("--seconds", so->seconds, "seconds of skeletons per run (default 60)")->check(kPositive);
  sc->add_option("-p,--param", so->params, "further sim parameter KEY=VALUE (repeatable; e.g. people=2)");
  sc->add_option("--target-deg", so->target_deg, "a sensor within this rotation error (default 1)")->check(kPositive);
  sc->add_option("--target-cm", so->target_cm, "... and this translation error (default 2)")->check(kPositive);
  sc->add_flag("--floor", so->floor,
               "also search, from each sensor's true pose, the pose its skeletons and the reference's agree on best "
               "(lowest median distance): how far the data themselves are from the truth (slower)");
  sc->add_flag("--json", so->json, "machine-readable results: a summary and every run");
  sc->callback([so, &run] { run = [so] { return calib_sim(*so); }; });

  auto b = std::make_shared<BoardOptions>();
  auto* in = cal->add_subcommand("intrinsics", "Camera intrinsics from images of a checkerboard (OpenCV calibrateCamera)");
  in->add_option("images", b->images, "images of the board, 15 or more, tilted every way")->required()->check(CLI::ExistingFile);
  in->add_option("--board", b->size, "inner corners COLSxROWS (default 9x6)");
  in->add_option("--square", b->square_m, "square size, m (default 0.08)")->check(kPositive);
  in->add_option("--out", b->out, "write an intrinsics file (YAML), e.g. DIR/intrinsics.yaml for calib board");
  in->add_flag("--json", b->json, "machine-readable result");
  in->callback([b, &run] { run = [b] { return calib_intrinsics(*b); }; });

  auto* bo = cal->add_subcommand(
      "board",
      "Extrinsics from a checkerboard: between two sensors that both see it, or of one sensor to a motion-capture frame "
      "(--world-markers); corners found in each colour image, lifted to 3-D with the depth image, all views aligned by SVD");
  bo->add_option("ref_dir", b->ref_dir, "reference sensor's views: NAME_color.png + NAME_depth.png (16-bit mm)")
      ->required()
      ->check(CLI::ExistingDirectory);
  bo->add_option("other_dir", b->other_dir, "the other sensor's views, same NAMEs taken at the same moments (omit with --world-markers)")
      ->check(CLI::ExistingDirectory);
  bo->add_option("--world-markers", b->world_markers,
                 "board markers file (markers on the board, and per view where motion capture saw them): calibrate "
                 "REF_DIR's sensor (--ref) to the motion-capture frame")
      ->check(CLI::ExistingFile);
  bo->add_option("--ref", b->ref, "reference sensor id (default sensor1)");
  bo->add_option("--other", b->other, "other sensor id (default sensor2)");
  bo->add_option("--board", b->size, "inner corners COLSxROWS (default 9x6)");
  bo->add_option("--square", b->square_m, "square size, m (default 0.08)")->check(kPositive);
  bo->add_option("--ref-intrinsics", b->ref_intrinsics, "intrinsics file (default: REF_DIR/intrinsics.yaml)");
  bo->add_option("--other-intrinsics", b->other_intrinsics, "intrinsics file (default: OTHER_DIR/intrinsics.yaml)");
  bo->add_option("--ref-pose", b->ref_pose, "a calibration file with the reference sensor's pose in the world")
      ->check(CLI::ExistingFile);
  bo->add_option("--out", b->out, "write a calibration file (YAML)");
  bo->add_flag("--json", b->json, "machine-readable result");
  bo->callback([b, &run] { run = [b] { return calib_board(*b); }; });

  auto ro = std::make_shared<RobotOptions>();
  auto* rb = cal->add_subcommand(
      "robot",
      "Extrinsics of the sensors in the robot's frame: a checkerboard on the tool moved through poses "
      "(--tool-poses, one directory of views per sensor), or a person's hand held still at the tool at several "
      "places (--hand RECORDING); RANSAC and SVD, residuals, a verdict and a calibration file in the world the "
      "robot's base stands in (--base)");
  rb->add_option("directories", ro->dirs, "board on the tool: one directory per sensor, named by its id, with "
                                          "NAME_color.png + NAME_depth.png (16-bit mm) for each view NAME")
      ->check(CLI::ExistingDirectory);
  rb->add_option("--tool-poses", ro->tool_poses, "board on the tool: the tool's pose in the base frame for each view NAME "
                                                 "and the board's mount on the tool (YAML, components/calib/README.md)")
      ->check(CLI::ExistingFile);
  rb->add_option("--hand", ro->hand_recording, "hand at the tool: an MCAP recording of skelgraph/robot/state and "
                                               "skelgraph/skeleton/raw while a person held a hand on the tool, still, "
                                               "at several places")
      ->check(CLI::ExistingFile);
  rb->add_option("--which-hand", ro->hand, "the hand held at the tool: right, left or either (default either: a sensor "
                                           "behind the person reports the hands swapped)")
      ->check(CLI::IsMember({"right", "left", "either"}));
  rb->add_option("--cell", ro->cell,
                 "hand at the tool: a calibration file with the sensors' poses relative to each other (e.g. from calib "
                 "skeleton): every sensor's holds in that frame, one fit for the whole cell")
      ->check(CLI::ExistingFile);
  rb->add_option("--hold", ro->hold_s, "hand at the tool: both still this long make a pair, s (default 1)")->check(kPositive);
  rb->add_option("--inlier-cm", ro->inlier_cm, "hand at the tool: a pair agrees within this under a good pose (default 8)")->check(kPositive);
  rb->add_option("--base", ro->base, "where the robot's base stands in the world: x,y,z (m; y up) and yaw (deg), as "
                                     "the robot component's `base` (default 0,0,1.5,180)");
  rb->add_option("--intrinsics", ro->intrinsics, "board: intrinsics file for every directory (default: DIR/intrinsics.yaml)")
      ->check(CLI::ExistingFile);
  rb->add_option("--board", ro->size, "inner corners COLSxROWS (default 9x6)");
  rb->add_option("--square", ro->square_m, "square size, m (default 0.08)")->check(kPositive);
  rb->add_option("--truth", ro->truth, "a calibration file with the true poses (the simulator's): report each sensor's error")
      ->check(CLI::ExistingFile);
  rb->add_option("--out", ro->out, "write a calibration file (YAML)");
  rb->add_flag("--json", ro->json, "machine-readable result");
  rb->callback([ro, &run] { run = [ro] { return calib_robot(*ro); }; });
}

}  // namespace skelgraph::cli
