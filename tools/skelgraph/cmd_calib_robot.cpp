// skelgraph calib robot: the sensors in the robot's frame, from a board on
// the tool (its views with the tool poses the robot reported) or from a
// person's hand held at the tool (a recording of the robot's state and the
// skeletons).

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "cmd_calib.hpp"
#include "skelgraph/calib/board.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/calib/inputs.hpp"
#include "skelgraph/calib/sim_check.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::cli::calib_cmd {

namespace {

// The hand at the tool (calib/inputs.hpp); a bad recording is a usage error.
calib::HandInput read_hand_input(const std::string& path, const std::vector<skeleton::JointId>& joints) {
  try {
    return calib::read_hand_input(path, joints);
  } catch (const calib::InputError& e) {
    throw UsageError(e.what());
  }
}

}  // namespace

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
    bool good = false;        // calib::board_fit_good / hand_fit_good
  };
  std::vector<Result> results;
  std::vector<std::string> failed;  // sensors without a fit, with the reason
  if (hand_mode) {
    // Either hand by default: a tracker that sees the person's back swaps left and right,
    // and the hand not at the tool is an outlier RANSAC leaves out.
    std::vector<skeleton::JointId> joints;
    if (o.hand != "left") joints.push_back(skeleton::JointId::RightHand);
    if (o.hand != "right") joints.push_back(skeleton::JointId::LeftHand);
    const auto in = read_hand_input(o.hand_recording, joints);
    calib::HandCalibOptions ho;
    ho.holds.hold_s = o.hold_s;
    ho.inlier_m = o.inlier_cm / 100.0;
    ho.world_from_base = world_from_base;
    if (!o.cell.empty()) {
      ho.cell = prior_poses(o.cell);
      ho.cell_name = o.cell;
    }
    auto hc = calib::calibrate_hand_at_tool(in.tool, in.hands, ho);
    failed = std::move(hc.failed);
    for (auto& f : hc.fits) {
      const bool good = calib::hand_fit_good(f);
      results.push_back({f.sensor, std::move(f.fit), {}, f.holds, f.places, f.places_agreeing, good});
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
        auto fit = calib::fit_board_on_tool(corners, base_from_board, board.object_points());
        const bool good = calib::board_fit_good(fit);
        results.push_back({sensor, std::move(fit), skipped, names.size(), 0, 0, good});
      } catch (const calib::CalibError& e) {
        failed.push_back(sensor + ": " + e.what() + (skipped.empty() ? "" : " (" + skipped.front() + ")"));
      }
    }
  }

  nlohmann::json sensors = nlohmann::json::array();
  calib::CalibFile file;
  file.comment = std::string("written by skelgraph calib robot ") +
                 (hand_mode ? "--hand " + o.hand_recording : "--tool-poses " + o.tool_poses) + " --base " + o.base;
  bool all_good = failed.empty() && !results.empty();
  for (const auto& r : results) {
    const auto& f = r.fit.ransac.fit;
    const bool good = r.good;
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

}  // namespace skelgraph::cli::calib_cmd
