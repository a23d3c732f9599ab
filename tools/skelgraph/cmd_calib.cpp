// skelgraph calib skeleton|sim|intrinsics|board|robot: the command line
// (cmd_calib_*.cpp run each subcommand) and the helpers they share. No DDS.

#include <cmath>
#include <filesystem>

#include "cmd_calib.hpp"
#include "skelgraph/calib/rigid.hpp"
#include "skelgraph/playback/readers.hpp"

namespace skelgraph::cli {
namespace calib_cmd {

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


void write_calib(const std::string& out, const calib::CalibFile& f) {
  try {
    calib::write_calib_file(out, f);
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
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


}  // namespace calib_cmd

using namespace calib_cmd;

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
