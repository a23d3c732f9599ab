// skelgraph calib intrinsics|board: camera intrinsics from checkerboard
// images, and extrinsics from a checkerboard both sensors see (colour +
// depth), or one sensor into a motion-capture frame by the board's markers.

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


calib::Board board_of(const BoardOptions& o) {
  try {
    return calib::Board::parse(o.size, o.square_m);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
}

}  // namespace

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

}  // namespace skelgraph::cli::calib_cmd
