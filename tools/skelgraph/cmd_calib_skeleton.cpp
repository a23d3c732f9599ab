// skelgraph calib skeleton: sensor extrinsics from the skeletons the sensors
// report of the same people (no board), one pair or the whole cell, with
// residuals, a hold-out check, a verdict and a file fusion can use
// (calib/skeleton_run.hpp; the step and its acceptance policy:
// calib/calibration_step.hpp).

#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cmd_calib.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/calib/inputs.hpp"
#include "skelgraph/calib/skeleton_run.hpp"
#include "skelgraph/playback/readers.hpp"

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

// One input: its skeletons, the previous poses (--prior), then calib::calibrate_skeletons.
nlohmann::json calibrate_one(const std::string& path, const SkelOptions& o, std::vector<skeleton::SensorPose>* results) {
  Input in = read_input(path, o.format, o.on_error);
  if (o.prior == "shared") {
    for (const auto& [id, v] : in.by_sensor) in.poses[id] = Eigen::Isometry3d::Identity();
  } else if (!o.prior.empty()) {
    in.poses = prior_poses(o.prior);
  }
  calib::SkeletonRun run;
  run.ref = o.ref;
  run.other = o.other;
  run.threshold_m = o.threshold_m;
  run.robust_scale_m = o.robust_scale_m;
  run.clock_search_ms = o.clock_search_ms;
  run.holdout = o.holdout;
  run.best_rigid = o.best_rigid;
  run.best_rigid_starts = o.best_rigid_starts;
  try {
    return calib::calibrate_skeletons(path, in, run, results);
  } catch (const calib::InputError& e) {
    throw UsageError(e.what());
  }
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
