// skelgraph sim table: the simulator against the thesis's Tables 5.1/5.2
// (one sensor, each scenario and tracker profile); skelgraph sim export: a
// whole run written to generic CSV files. No DDS.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include <opencv2/core.hpp>  // cv::RNG: the sequences the simulated boards and tool poses were drawn from

#include "skelgraph/calib/board.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/playback/bvh.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"
#include "skelgraph/robot/arm.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/sim/realism.hpp"
#include "skelgraph/sim/sim_component.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/sim/tracker.hpp"

namespace skelgraph::cli {

sim::SimConfig sim_config(const std::vector<std::string>& assignments, const char* what,
                          const std::vector<runtime::RawParam>& extra) {
  runtime::ParamSchema schema;
  sim::add_sim_params(schema);
  try {
    std::vector<runtime::RawParam> raw;
    for (const auto& p : assignments) raw.push_back(runtime::parse_param_assignment(p, "--param " + p));
    raw.insert(raw.end(), extra.begin(), extra.end());
    auto cfg = sim::sim_config_from(schema.resolve(raw, what));
    sim::Simulation probe(cfg);  // checks the configuration
    return cfg;
  } catch (const runtime::ParamError& e) {
    throw UsageError(e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

namespace {

// A board view as BASE_color.png (and BASE_depth.png).
void write_view(const std::filesystem::path& base, const calib::BoardView& view, bool depth) {
  try {
    calib::write_png(base.string() + "_color.png", view.grey);
    if (depth) calib::write_png(base.string() + "_depth.png", view.depth_mm);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
}

int table(const sim::RealismOptions& opt, bool json, bool check) {
  nlohmann::json out = nlohmann::json::array();
  int misses = 0, cells = 0;
  if (!json) {
    std::printf("Detection %% (sim / thesis) and mean error of tracked joints, cm (sim / thesis); '*' = outside tolerance\n");
    std::printf("seed %llu, %d repeat(s) of each scenario, one sensor 2 m away\n",
                static_cast<unsigned long long>(opt.seed), opt.repeats);
  }
  for (const auto& profile : sim::TrackerProfile::names()) {
    if (!json) {
      std::printf("\n%-6s %-10s", profile.c_str(), "group");
      for (const auto& s : sim::kThesisScenarios) std::printf(" | %-21s", s.c_str());
      std::printf("\n");
    }
    std::vector<sim::Figures> sims, refs;
    Progress progress;
    for (const auto& s : sim::kThesisScenarios) {
      progress("simulating " + profile + " " + s + "...");
      sims.push_back(sim::simulate_figures(s, profile, opt));
      refs.push_back(sim::thesis_figures(s, profile));
    }
    progress.done(false);
    for (std::size_t g = 0; g < sim::kGroupCount; ++g) {
      if (!json) std::printf("%-6s %-10s", "", sim::group_names()[g]);
      for (std::size_t k = 0; k < sims.size(); ++k) {
        const auto& a = sims[k][g];
        const auto& b = refs[k][g];
        const bool det_ok = sim::detection_close(a.detection_pct, b.detection_pct);
        const bool err_ok = std::isfinite(a.error_cm) && sim::error_close(a.error_cm, b.error_cm);
        misses += (det_ok ? 0 : 1) + (err_ok ? 0 : 1);
        cells += 2;
        if (json) {
          out.push_back({{"profile", profile}, {"scenario", sim::kThesisScenarios[k]}, {"group", sim::group_names()[g]},
                         {"sim_detection_pct", a.detection_pct}, {"thesis_detection_pct", b.detection_pct},
                         {"sim_error_cm", std::isfinite(a.error_cm) ? nlohmann::json(a.error_cm) : nlohmann::json()},
                         {"thesis_error_cm", b.error_cm}, {"detection_close", det_ok}, {"error_close", err_ok}});
        } else {
          std::printf(" | %3.0f/%3.0f%c %5.1f/%5.1f%c", a.detection_pct, b.detection_pct, det_ok ? ' ' : '*', a.error_cm,
                      b.error_cm, err_ok ? ' ' : '*');
        }
      }
      if (!json) std::printf("\n");
    }
  }
  if (json) {
    std::printf("%s\n", nlohmann::json{{"seed", opt.seed}, {"repeats", opt.repeats}, {"cells", cells},
                                       {"outside_tolerance", misses}, {"rows", out}}
                            .dump(2)
                            .c_str());
  } else {
    std::printf("\n%d of %d figures outside tolerance (detection: 20 points; error: factor 2 or 6 cm)\n", misses, cells);
  }
  return check && misses > 0 ? 1 : 0;
}

void write_file(const std::filesystem::path& path, const playback::Recording& rec) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  playback::write_generic_csv(rec, out);
  if (!out.flush()) throw std::runtime_error("error writing " + path.string());
}

// The simulated sensors' true poses, as a calibration file says them.
calib::CalibFile true_poses(const sim::SimConfig& cfg, const std::string& comment) {
  calib::CalibFile f;
  f.comment = comment;
  for (const auto& s : cfg.sensors) {
    skeleton::SensorPose p;
    p.sensor_id = s.id;
    p.pose = s.world_from_sensor();
    p.method = "ground_truth";
    f.sensors.push_back(p);
  }
  return f;
}

// The simulated sensors' true poses as a calibration file.
int write_poses(const std::vector<std::string>& assignments, const std::string& out, bool json) {
  const auto cfg = sim_config(assignments, "sim poses");
  const auto f = true_poses(cfg, "the simulator's true sensor poses (skelgraph sim poses)");
  try {
    calib::write_calib_file(out, f);
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
  if (json) std::printf("%s\n", nlohmann::json{{"out", out}, {"sensors", f.sensors.size()}}.dump(2).c_str());
  else std::printf("%s: %zu sensor pose(s)\n", out.c_str(), f.sensors.size());
  return 0;
}

// Synthetic checkerboard views of the simulated cell, to calibrate from:
// DIR/<sensor>/NNN_color.png + NNN_depth.png (the board where every sensor
// sees it, the same NNN at the same moment), DIR/<sensor>/intrinsics/ (views
// for that sensor's intrinsics), and the truth: DIR/truth.yaml (poses) and
// DIR/<sensor>/intrinsics_truth.yaml; and DIR/markers.yaml, the board's
// motion-capture markers in each shared view (for calib board --world-markers).
struct BoardsOpts {
  std::string dir, size = "9x6";
  std::vector<std::string> params;
  double square_m = 0.08, grey_noise = 2.0, depth_noise = 1.0;
  int views = 20, intrinsics_views = 15;
  std::uint64_t seed = 1;
  std::string robot_base;  // --robot: the board on the robot's tool
  double tool_noise_mm = 1.0, tool_noise_deg = 0.1;  // ... and the error of the tool poses it reports
  bool json = false;
};

// --robot: a checkerboard on the tool of a simulated UR5e standing at `base`,
// moved through poses where the board faces one sensor: `views` poses per
// sensor (any other sensor that sees a pose gets its view too), drawn at
// random joint angles with the whole arm above the floor. DIR/<sensor>/
// NNN_color.png + NNN_depth.png + intrinsics.yaml (the true intrinsics),
// DIR/tool_poses.yaml (what the robot reports, and the mount), DIR/truth.yaml.
// The arm itself is not drawn: it hides nothing of the board here.
int write_robot_boards(const BoardsOpts& o, const sim::SimConfig& cfg, const calib::Board& board, const calib::Intrinsics& k) {
  Eigen::Isometry3d world_from_base;
  try {
    world_from_base = robot::parse_base(o.robot_base);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--robot: ") + e.what());
  }
  const auto arm = robot::ArmModel::ur5e();
  calib::ToolPoses poses;
  poses.robot = arm.name;
  // On the flange, the printed side facing out along the tool's z, its middle 1 cm beyond the tool point.
  const Eigen::Vector3d middle(0.5 * (board.cols - 1) * board.square_m, 0.5 * (board.rows - 1) * board.square_m, 0);
  poses.tool_from_board.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
  poses.tool_from_board.translation() = Eigen::Vector3d(0, 0, 0.01) - poses.tool_from_board.linear() * middle;
  std::vector<Eigen::Isometry3d> sensors;
  for (const auto& s : cfg.sensors) sensors.push_back(s.world_from_sensor());
  cv::RNG rng(o.seed);
  std::vector<robot::Joints> chosen;
  std::vector<Eigen::Isometry3d> boards;  // world_from_board
  for (std::size_t si = 0; si < sensors.size(); ++si) {
    int found = 0;
    for (int tries = 0; found < o.views && tries < 2'000'000; ++tries) {
      robot::Joints q;
      q << rng.uniform(-M_PI, M_PI), rng.uniform(-M_PI, 0.0), rng.uniform(-2.6, 2.6), rng.uniform(-M_PI, M_PI),
          rng.uniform(-M_PI, M_PI), rng.uniform(-M_PI, M_PI);
      const auto f = robot::forward(arm, q);
      bool above = true;
      for (std::size_t i = 2; i < f.size(); ++i) above = above && (world_from_base * f[i].translation()).y() > 0.15;  // 0, 1: the base
      const Eigen::Isometry3d wb = world_from_base * f[7] * poses.tool_from_board;
      for (const auto& p : board.object_points()) above = above && (wb * p).y() > 0.15;
      if (!above || !calib::board_in_view(sensors[si], wb, board, k)) continue;
      chosen.push_back(q);
      boards.push_back(wb);
      ++found;
    }
    if (found < o.views) {
      throw UsageError(cfg.sensors[si].id + ": the robot at " + o.robot_base + " shows it the board in only " +
                       std::to_string(found) + " poses (too far from its reach?)");
    }
  }
  std::size_t images = 0;
  char name[32];
  std::vector<std::size_t> per_sensor(sensors.size(), 0);
  for (std::size_t si = 0; si < sensors.size(); ++si) {
    const std::filesystem::path dir = std::filesystem::path(o.dir) / cfg.sensors[si].id;
    std::filesystem::create_directories(dir);
    calib::write_intrinsics_file((dir / "intrinsics.yaml").string(), k, 0.0, 0, "the simulated camera's true intrinsics");
    for (std::size_t v = 0; v < boards.size(); ++v) {
      if (!calib::board_in_view(sensors[si], boards[v], board, k)) continue;
      const auto view = calib::render_board_view(board, k, calib::camera_from_board(sensors[si], boards[v]), o.grey_noise,
                                                 o.depth_noise, o.seed * 1000003 + 1000 * si + v);
      std::snprintf(name, sizeof name, "%03zu", v);
      write_view(dir / name, view, true);
      images += 2;
      ++per_sensor[si];
    }
  }
  // What the robot reports: its true tool pose with an error (a robot's
  // absolute accuracy is millimetres, far worse than its repeatability).
  for (std::size_t v = 0; v < chosen.size(); ++v) {
    std::snprintf(name, sizeof name, "%03zu", v);
    Eigen::Isometry3d reported = robot::forward(arm, chosen[v])[7];
    const Eigen::Vector3d axis = Eigen::Vector3d(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1)).normalized();
    reported.linear() = reported.linear() * Eigen::AngleAxisd(rng.gaussian(o.tool_noise_deg * M_PI / 180.0), axis).toRotationMatrix();
    reported.translation() += 1e-3 * o.tool_noise_mm * Eigen::Vector3d(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1));
    poses.base_from_tool[name] = reported;
  }
  calib::write_tool_poses((std::filesystem::path(o.dir) / "tool_poses.yaml").string(), poses,
                          "the simulated robot's tool poses (skelgraph sim boards --robot " + o.robot_base + ")");
  calib::write_calib_file((std::filesystem::path(o.dir) / "truth.yaml").string(),
                          true_poses(cfg, "the simulator's true sensor poses (skelgraph sim boards --robot)"));
  nlohmann::json views_per_sensor;
  for (std::size_t si = 0; si < sensors.size(); ++si) views_per_sensor[cfg.sensors[si].id] = per_sensor[si];
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"dir", o.dir}, {"robot_poses", chosen.size()}, {"views", views_per_sensor}, {"images", images}}.dump(2).c_str());
  } else {
    std::printf("%s: %zu robot poses, %zu images for %zu sensors; tool poses in tool_poses.yaml, truth in truth.yaml\n",
                o.dir.c_str(), chosen.size(), images, sensors.size());
  }
  return 0;
}

int write_boards(const BoardsOpts& o) {
  const auto cfg = sim_config(o.params, "sim boards");
  calib::Board board;
  try {
    board = calib::Board::parse(o.size, o.square_m);
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  }
  const calib::Intrinsics k;  // Kinect-like
  if (!o.robot_base.empty()) return write_robot_boards(o, cfg, board, k);
  std::vector<Eigen::Isometry3d> sensors;
  for (const auto& s : cfg.sensors) sensors.push_back(s.world_from_sensor());
  const Eigen::Vector3d centre(0, 1.2, 0);
  std::vector<Eigen::Isometry3d> shared;
  try {
    shared = calib::board_poses_seen_by(sensors, board, k, o.views, centre, o.seed);
  } catch (const calib::CalibError& e) {
    throw UsageError(std::string(e.what()) + " (sensors too far apart for one board?)");
  }
  std::size_t images = 0;
  for (std::size_t si = 0; si < sensors.size(); ++si) {
    const std::filesystem::path dir = std::filesystem::path(o.dir) / cfg.sensors[si].id;
    std::filesystem::create_directories(dir / "intrinsics");
    char name[32];
    for (std::size_t v = 0; v < shared.size(); ++v) {
      const auto view = calib::render_board_view(board, k, calib::camera_from_board(sensors[si], shared[v]), o.grey_noise,
                                                 o.depth_noise, o.seed * 1000003 + 1000 * si + v);
      std::snprintf(name, sizeof name, "%03zu", v);
      write_view(dir / name, view, true);
      images += 2;
    }
    const Eigen::Vector3d in_front = cfg.sensors[si].position + 0.55 * (centre - cfg.sensors[si].position);
    const auto own = calib::board_poses_seen_by({sensors[si]}, board, k, o.intrinsics_views, in_front, o.seed + 7 * si + 1);
    for (std::size_t v = 0; v < own.size(); ++v) {
      const auto view = calib::render_board_view(board, k, calib::camera_from_board(sensors[si], own[v]), o.grey_noise,
                                                 o.depth_noise, o.seed * 7919 + 1000 * si + v);
      std::snprintf(name, sizeof name, "%03zu", v);
      write_view(dir / "intrinsics" / name, view, false);
      ++images;
    }
    calib::write_intrinsics_file((dir / "intrinsics_truth.yaml").string(), k, 0.0, 0, "the simulated camera's true intrinsics");
    if (!o.json) std::fprintf(stderr, "%s: %zu shared views, %zu intrinsics views\n", cfg.sensors[si].id.c_str(), shared.size(), own.size());
  }
  calib::write_calib_file((std::filesystem::path(o.dir) / "truth.yaml").string(),
                          true_poses(cfg, "the simulator's true sensor poses (skelgraph sim boards)"));
  // Motion-capture markers on the board (four round its edge, one on a
  // stalk), seen in the world with 0.5 mm of noise.
  calib::BoardMarkers markers;
  const double w = (board.cols - 1) * board.square_m, h = (board.rows - 1) * board.square_m;
  markers.in_board = {{-0.12, -0.12, 0}, {w + 0.12, -0.12, 0}, {-0.12, h + 0.12, 0}, {w + 0.12, h + 0.1, 0}, {0.5 * w, -0.12, -0.05}};
  cv::RNG mrng(o.seed + 99);
  char vname[32];
  for (std::size_t v = 0; v < shared.size(); ++v) {
    std::snprintf(vname, sizeof vname, "%03zu", v);
    auto& pts = markers.in_world[vname];
    for (const auto& m : markers.in_board) {
      pts.push_back(shared[v] * m + Eigen::Vector3d(mrng.gaussian(5e-4), mrng.gaussian(5e-4), mrng.gaussian(5e-4)));
    }
  }
  calib::write_board_markers((std::filesystem::path(o.dir) / "markers.yaml").string(), markers,
                             "the board's motion-capture markers in every shared view (skelgraph sim boards)");
  if (o.json) std::printf("%s\n", nlohmann::json{{"dir", o.dir}, {"sensors", sensors.size()}, {"views", shared.size()}, {"images", images}}.dump(2).c_str());
  else std::printf("%s: %zu images for %zu sensors, truth in truth.yaml\n", o.dir.c_str(), images, sensors.size());
  return 0;
}

// A person's hand held at a robot's tool, to calibrate from (calib robot
// --hand): a simulation whose first person's right hand the tool touches
// wherever the hand is (the tool point `contact_cm` beyond the hand joint
// along the forearm, where the palm closes round it); the robot's reported
// position has an error of `tool_noise_mm` that varies smoothly over the
// workspace (a robot's absolute accuracy). Written as a recording: the
// sensors' skeletons (skeleton/raw), the truth, the true sensor poses
// (calibration) and the tool (robot/state, world, at the truth's rate).
struct HandOpts {
  std::string out;
  std::vector<std::string> params;
  double contact_cm = 3.0, tool_noise_mm = 1.0;
  bool json = false;
};

int write_hand_at_tool(const HandOpts& o) {
  const auto cfg = sim_config(o.params, "sim hand-at-tool");
  sim::Simulation sim(cfg);
  recording::BagWriter bag(o.out);
  bag.write_metadata("source", {{"source", "skelgraph sim hand-at-tool"}, {"scenario", cfg.scenario.name},
                                {"seed", std::to_string(cfg.scenario.seed)}});
  for (const auto& p : true_poses(cfg, "").sensors) {
    bag.write(runtime::topics::kCalibration.name, skeleton::to_msg(p), static_cast<std::uint64_t>(cfg.epoch_ns),
              static_cast<std::uint64_t>(cfg.epoch_ns));
  }
  cv::RNG rng(cfg.scenario.seed + 17);
  const Eigen::Vector3d phase(rng.uniform(0.0, 2 * M_PI), rng.uniform(0.0, 2 * M_PI), rng.uniform(0.0, 2 * M_PI));
  std::size_t states = 0, raw = 0;
  Progress progress(!o.json);
  for (double t = 5.0;; t += 5.0) {
    for (auto& e : sim.advance(t)) {
      // Logged when the world clock says (a recorder's clock); sensors stamp on their own.
      const auto stamp = static_cast<std::uint64_t>(cfg.epoch_ns + static_cast<std::int64_t>(e.t * 1e9));
      if (e.kind == sim::SimEvent::Kind::Raw) {
        bag.write(runtime::topics::kSkeletonRaw.name, skeleton::to_msg(e.skeleton), stamp, stamp);
        ++raw;
      } else if (e.kind == sim::SimEvent::Kind::Truth) {
        bag.write(runtime::topics::kSkeletonTruth.name, skeleton::to_msg(e.skeleton), stamp, stamp);
        if (e.actor != sim.scenario().at(e.t).actors.front().person_id) continue;
        const auto& hand = e.skeleton[skeleton::JointId::RightHand].position;
        const auto& elbow = e.skeleton[skeleton::JointId::RightElbow].position;
        const Eigen::Vector3d touch = hand + 0.01 * o.contact_cm * (hand - elbow).normalized();
        // The robot's absolute error: smooth over the workspace (the same at the same place), sd tool_noise_mm.
        const Eigen::Vector3d err(std::sin(7 * touch.x() + phase.x()), std::sin(7 * touch.y() + phase.y()),
                                  std::sin(7 * touch.z() + phase.z()));
        const Eigen::Vector3d tool = touch + 1e-3 * o.tool_noise_mm * std::sqrt(2.0) * err;
        msg::RobotState st;
        st.robot_id("robot1");
        st.model("UR5e");
        st.stamp_ns(e.skeleton.stamp_ns);
        st.tool_position().x(tool.x());
        st.tool_position().y(tool.y());
        st.tool_position().z(tool.z());
        bag.write(runtime::topics::kRobotState.name, st, stamp, stamp);
        ++states;
      }
    }
    char text[64];
    std::snprintf(text, sizeof text, "simulated %.0f of %.0f s", std::min(t, sim.duration()), sim.duration());
    progress(text, sim.finished());
    if (sim.finished()) break;
  }
  bag.close();
  const nlohmann::json j{{"out", o.out}, {"duration_s", sim.duration()}, {"robot_states", states}, {"raw_skeletons", raw}};
  if (o.json) std::printf("%s\n", j.dump(2).c_str());
  else std::printf("%s: %.0f s, %zu robot states, %zu sensor skeletons\n", o.out.c_str(), sim.duration(), states, raw);
  return 0;
}

int export_run(const std::vector<std::string>& assignments, const std::string& dir, bool json) {
  const auto cfg = sim_config(assignments, "sim export");
  sim::Simulation sim(cfg);
  std::map<std::string, std::string> meta{{"source", "skelgraph sim"},
                                          {"scenario", cfg.scenario.name},
                                          {"seed", std::to_string(cfg.scenario.seed)},
                                          {"repeats", std::to_string(cfg.scenario.repeats)},
                                          {"people", std::to_string(cfg.scenario.people)},
                                          {"profile", cfg.profile}};
  playback::Recording truth;
  truth.format = "generic";
  truth.metadata = meta;
  truth.metadata["frame"] = "world";
  std::vector<playback::Recording> raw(cfg.sensors.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const auto& s = cfg.sensors[i];
    raw[i].format = "generic";
    raw[i].metadata = meta;
    const Eigen::Vector3d p = s.position;
    raw[i].metadata["sensor_pose"] = std::to_string(p.x()) + "," + std::to_string(p.y()) + "," + std::to_string(p.z()) +
                                     " yaw " + std::to_string(s.yaw * 180.0 / M_PI) + " pitch " +
                                     std::to_string(s.pitch * 180.0 / M_PI);
    raw[i].metadata["clock_offset_ms"] = std::to_string(s.clock_offset_s * 1e3);
  }
  std::filesystem::create_directories(dir);
  std::ofstream phases(std::filesystem::path(dir) / "phases.csv");
  phases << "stamp_ns,person_id,phase\n";
  const double step = 5.0;  // s of simulated time per batch (progress)
  Progress progress(!json);
  for (double t = step;; t += step) {
    for (auto& e : sim.advance(t)) {
      if (e.kind == sim::SimEvent::Kind::Truth) {
        for (const auto& a : sim.scenario().at(e.t).actors) {
          if (a.person_id == e.actor) phases << e.skeleton.stamp_ns << "," << a.person_id << "," << a.phase << "\n";
        }
        truth.frames.push_back(std::move(e.skeleton));
      } else {
        raw[e.sensor].frames.push_back(std::move(e.skeleton));
      }
    }
    char text[64];
    std::snprintf(text, sizeof text, "simulated %.0f of %.0f s", std::min(t, sim.duration()), sim.duration());
    progress(text, sim.finished());
    if (sim.finished()) break;
  }
  nlohmann::json files = nlohmann::json::object();
  write_file(std::filesystem::path(dir) / "truth.csv", truth);
  files["truth.csv"] = truth.frames.size();
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const auto name = "raw_" + cfg.sensors[i].id + ".csv";
    write_file(std::filesystem::path(dir) / name, raw[i]);
    files[name] = raw[i].frames.size();
  }
  // The truth as motion capture (BVH, cm, position channels): what `bag
  // import-bvh` reads, when one person is there from start to end at the truth rate.
  const auto evenly = [&] {
    if (truth.frames.size() < 2) return false;
    const auto step_ns = truth.frames[1].stamp_ns - truth.frames[0].stamp_ns;
    for (std::size_t i = 1; i < truth.frames.size(); ++i) {
      const auto d = truth.frames[i].stamp_ns - truth.frames[i - 1].stamp_ns;
      if (truth.frames[i].person_id != truth.frames[0].person_id || std::llabs(d - step_ns) > 1'000'000) return false;
    }
    return true;
  };
  if (evenly()) {
    std::ofstream bvh(std::filesystem::path(dir) / "truth.bvh");
    playback::write_position_bvh(truth.frames, 1e-9 * static_cast<double>(truth.frames[1].stamp_ns - truth.frames[0].stamp_ns), 100.0,
                                 bvh);
    if (!bvh.flush()) throw std::runtime_error("error writing truth.bvh");
    files["truth.bvh"] = truth.frames.size();
    files["truth.bvh first frame s"] = 1e-9 * static_cast<double>(truth.frames.front().stamp_ns);
  } else {
    files["truth.bvh"] = "not written: not one person from start to end at a steady rate";
  }
  if (!phases.flush()) throw std::runtime_error("error writing phases.csv");
  files["phases.csv"] = truth.frames.size();
  if (json) {
    std::printf("%s\n", nlohmann::json{{"directory", dir}, {"duration_s", sim.duration()}, {"rows", files}}.dump(2).c_str());
  } else {
    for (const auto& [name, rows] : files.items()) std::printf("%s/%s: %s rows\n", dir.c_str(), name.c_str(), rows.dump().c_str());
  }
  return 0;
}

}  // namespace

void add_sim_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* cmd = app.add_subcommand("sim", "Offline tools of the work-cell simulator");
  cmd->require_subcommand(1);
  struct Opts {
    sim::RealismOptions realism;
    bool json = false;
    bool check = false;
  };
  auto o = std::make_shared<Opts>();
  auto* t = cmd->add_subcommand("table", "Compare the simulator with the thesis's Tables 5.1/5.2 (one sensor)");
  t->add_option("--seed", o->realism.seed, "random seed");
  t->add_option("--repeats", o->realism.repeats, "repeats of each scenario")->check(CLI::Range(1, 100));
  t->add_option("--noise-scale", o->realism.noise_scale, "scale of the tracker's noise")->check(kNonNegative);
  t->add_flag("--json", o->json, "machine-readable output");
  t->add_flag("--check", o->check, "exit 1 if any figure is outside tolerance");
  t->callback([o, &run] { run = [o] { return table(o->realism, o->json, o->check); }; });

  struct ExportOpts {
    std::string dir;
    std::vector<std::string> params;
    bool json = false;
  };
  auto ho = std::make_shared<HandOpts>();
  auto* h = cmd->add_subcommand("hand-at-tool", "Simulate a person's hand held at a robot's tool, written as a recording "
                                                "(skeletons, truth, true poses, the tool's positions) for calib robot --hand");
  h->add_option("recording", ho->out, "MCAP file to write")->required();
  h->add_option("-p,--param", ho->params, "sim parameter as KEY=VALUE (scenario, layout, sensor_count, seed, ...)");
  h->add_option("--contact-cm", ho->contact_cm, "the tool point beyond the hand joint, along the forearm (default 3)")->check(kNonNegative);
  h->add_option("--tool-noise", ho->tool_noise_mm, "error of the reported tool positions, mm per axis (sd; default 1)")->check(kNonNegative);
  h->add_flag("--json", ho->json, "machine-readable summary");
  h->callback([ho, &run] { run = [ho] { return write_hand_at_tool(*ho); }; });

  auto e = std::make_shared<ExportOpts>();
  auto* x = cmd->add_subcommand("export", "Run a simulation offline and write it as generic CSV (truth, each sensor, phases), and the truth as motion capture (truth.bvh)");
  x->add_option("directory", e->dir, "output directory (created)")->required();
  x->add_option("-p,--param", e->params, "sim parameter as KEY=VALUE, as in `skelgraph components` (repeatable)");
  x->add_flag("--json", e->json, "machine-readable summary");
  x->callback([e, &run] { run = [e] { return export_run(e->params, e->dir, e->json); }; });

  auto po = std::make_shared<ExportOpts>();
  auto* ps = cmd->add_subcommand("poses", "Write the simulated sensors' true poses as a calibration file (YAML)");
  ps->add_option("file", po->dir, "calibration file to write")->required();
  ps->add_option("-p,--param", po->params, "sim parameter as KEY=VALUE (sensor_count, sensors)");
  ps->add_flag("--json", po->json, "machine-readable summary");
  ps->callback([po, &run] { run = [po] { return write_poses(po->params, po->dir, po->json); }; });

  auto bo = std::make_shared<BoardsOpts>();
  auto* b = cmd->add_subcommand("boards", "Render synthetic checkerboard views (colour + depth) of the simulated cell to calibrate from");
  b->add_option("directory", bo->dir, "output directory (created)")->required();
  b->add_option("-p,--param", bo->params, "sim parameter as KEY=VALUE (sensor_count, sensors)");
  b->add_option("--views", bo->views, "views every sensor sees (default 20)")->check(CLI::Range(3, 500));
  b->add_option("--intrinsics-views", bo->intrinsics_views, "views per sensor for its intrinsics (default 15)")->check(CLI::Range(3, 500));
  b->add_option("--board", bo->size, "inner corners COLSxROWS (default 9x6)");
  b->add_option("--square", bo->square_m, "square size, m (default 0.08)")->check(kPositive);
  b->add_option("--grey-noise", bo->grey_noise, "image noise, grey levels (default 2)")->check(kNonNegative);
  b->add_option("--depth-noise", bo->depth_noise, "scale of Kinect-like depth noise (default 1)")->check(kNonNegative);
  b->add_option("--seed", bo->seed, "random seed");
  b->add_option("--robot", bo->robot_base,
                "X,Y,Z,YAW: the board on the tool of a simulated UR5e whose base stands there (as the robot component's "
                "`base`), --views poses facing each sensor, and the tool poses the robot reports (for calib robot)");
  b->add_option("--tool-noise", bo->tool_noise_mm, "with --robot: error of the reported tool positions, mm per axis (sd; default 1)")
      ->check(kNonNegative);
  b->add_option("--tool-noise-deg", bo->tool_noise_deg, "with --robot: error of the reported tool orientations, deg (sd; default 0.1)")
      ->check(kNonNegative);
  b->add_flag("--json", bo->json, "machine-readable summary");
  b->callback([bo, &run] { run = [bo] { return write_boards(*bo); }; });
}

}  // namespace skelgraph::cli
