#include "skelgraph/calib/sim_boards.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <opencv2/core.hpp>  // cv::RNG: the sequences the simulated boards and tool poses were drawn from

#include "skelgraph/robot/arm.hpp"

namespace skelgraph::calib {

namespace {
// A board view as BASE_color.png (and BASE_depth.png).
void write_view(const std::filesystem::path& base, const BoardView& view, bool depth) {
  write_png(base.string() + "_color.png", view.grey);
  if (depth) write_png(base.string() + "_depth.png", view.depth_mm);
}

std::string view_name(std::size_t v) {
  char name[32];
  std::snprintf(name, sizeof name, "%03zu", v);
  return name;
}
}  // namespace

CalibFile true_poses(const sim::SimConfig& cfg, const std::string& comment) {
  CalibFile f;
  f.comment = comment;
  for (const auto& s : cfg.sensors) f.sensors.push_back(s.true_pose());
  return f;
}

SimBoardsSummary write_sim_boards(const sim::SimConfig& cfg, const SimBoardsOptions& o) {
  const Intrinsics k;  // Kinect-like
  const auto& board = o.board;
  std::vector<Eigen::Isometry3d> sensors;
  for (const auto& s : cfg.sensors) sensors.push_back(s.world_from_sensor());
  const Eigen::Vector3d centre(0, 1.2, 0);
  std::vector<Eigen::Isometry3d> shared;
  try {
    shared = board_poses_seen_by(sensors, board, k, o.views, centre, o.seed);
  } catch (const CalibError& e) {
    throw CalibError(std::string(e.what()) + " (sensors too far apart for one board?)");
  }
  SimBoardsSummary r;
  r.views = shared.size();
  for (std::size_t si = 0; si < sensors.size(); ++si) {
    const std::filesystem::path dir = std::filesystem::path(o.dir) / cfg.sensors[si].id;
    std::filesystem::create_directories(dir / "intrinsics");
    for (std::size_t v = 0; v < shared.size(); ++v) {
      const auto view = render_board_view(board, k, camera_from_board(sensors[si], shared[v]), o.grey_noise, o.depth_noise,
                                          o.seed * 1000003 + 1000 * si + v);
      write_view(dir / view_name(v), view, true);
      r.images += 2;
    }
    const Eigen::Vector3d in_front = cfg.sensors[si].position + 0.55 * (centre - cfg.sensors[si].position);
    const auto own = board_poses_seen_by({sensors[si]}, board, k, o.intrinsics_views, in_front, o.seed + 7 * si + 1);
    for (std::size_t v = 0; v < own.size(); ++v) {
      const auto view = render_board_view(board, k, camera_from_board(sensors[si], own[v]), o.grey_noise, o.depth_noise,
                                          o.seed * 7919 + 1000 * si + v);
      write_view(dir / "intrinsics" / view_name(v), view, false);
      ++r.images;
    }
    write_intrinsics_file((dir / "intrinsics_truth.yaml").string(), k, 0.0, 0, "the simulated camera's true intrinsics");
    r.intrinsics_views.emplace_back(cfg.sensors[si].id, own.size());
  }
  write_calib_file((std::filesystem::path(o.dir) / "truth.yaml").string(),
                   true_poses(cfg, "the simulator's true sensor poses (skelgraph sim boards)"));
  // Motion-capture markers on the board (four round its edge, one on a
  // stalk), seen in the world with 0.5 mm of noise.
  BoardMarkers markers;
  const double w = (board.cols - 1) * board.square_m, h = (board.rows - 1) * board.square_m;
  markers.in_board = {{-0.12, -0.12, 0}, {w + 0.12, -0.12, 0}, {-0.12, h + 0.12, 0}, {w + 0.12, h + 0.1, 0}, {0.5 * w, -0.12, -0.05}};
  cv::RNG mrng(o.seed + 99);
  for (std::size_t v = 0; v < shared.size(); ++v) {
    auto& pts = markers.in_world[view_name(v)];
    for (const auto& m : markers.in_board) {
      pts.push_back(shared[v] * m + Eigen::Vector3d(mrng.gaussian(5e-4), mrng.gaussian(5e-4), mrng.gaussian(5e-4)));
    }
  }
  write_board_markers((std::filesystem::path(o.dir) / "markers.yaml").string(), markers,
                      "the board's motion-capture markers in every shared view (skelgraph sim boards)");
  return r;
}

RobotBoardsSummary write_sim_robot_boards(const sim::SimConfig& cfg, const RobotBoardsOptions& o) {
  const Intrinsics k;  // Kinect-like
  const auto& b = o.boards;
  const auto& board = b.board;
  const auto& world_from_base = o.world_from_base;
  const auto arm = robot::ArmModel::ur5e();
  ToolPoses poses;
  poses.robot = arm.name;
  // On the flange, the printed side facing out along the tool's z, its middle 1 cm beyond the tool point.
  const Eigen::Vector3d middle(0.5 * (board.cols - 1) * board.square_m, 0.5 * (board.rows - 1) * board.square_m, 0);
  poses.tool_from_board.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
  poses.tool_from_board.translation() = Eigen::Vector3d(0, 0, 0.01) - poses.tool_from_board.linear() * middle;
  std::vector<Eigen::Isometry3d> sensors;
  for (const auto& s : cfg.sensors) sensors.push_back(s.world_from_sensor());
  cv::RNG rng(b.seed);
  std::vector<robot::Joints> chosen;
  std::vector<Eigen::Isometry3d> boards;  // world_from_board
  for (std::size_t si = 0; si < sensors.size(); ++si) {
    int found = 0;
    for (int tries = 0; found < b.views && tries < 2'000'000; ++tries) {
      robot::Joints q;
      q << rng.uniform(-M_PI, M_PI), rng.uniform(-M_PI, 0.0), rng.uniform(-2.6, 2.6), rng.uniform(-M_PI, M_PI),
          rng.uniform(-M_PI, M_PI), rng.uniform(-M_PI, M_PI);
      const auto f = robot::forward(arm, q);
      bool above = true;
      for (std::size_t i = 2; i < f.size(); ++i) above = above && (world_from_base * f[i].translation()).y() > 0.15;  // 0, 1: the base
      const Eigen::Isometry3d wb = world_from_base * f[7] * poses.tool_from_board;
      for (const auto& p : board.object_points()) above = above && (wb * p).y() > 0.15;
      if (!above || !board_in_view(sensors[si], wb, board, k)) continue;
      chosen.push_back(q);
      boards.push_back(wb);
      ++found;
    }
    if (found < b.views) {
      throw CalibError(cfg.sensors[si].id + ": the robot at " + o.base_text + " shows it the board in only " +
                       std::to_string(found) + " poses (too far from its reach?)");
    }
  }
  RobotBoardsSummary r;
  r.robot_poses = chosen.size();
  for (std::size_t si = 0; si < sensors.size(); ++si) {
    const std::filesystem::path dir = std::filesystem::path(b.dir) / cfg.sensors[si].id;
    std::filesystem::create_directories(dir);
    write_intrinsics_file((dir / "intrinsics.yaml").string(), k, 0.0, 0, "the simulated camera's true intrinsics");
    auto& seen = r.views[cfg.sensors[si].id];
    for (std::size_t v = 0; v < boards.size(); ++v) {
      if (!board_in_view(sensors[si], boards[v], board, k)) continue;
      const auto view = render_board_view(board, k, camera_from_board(sensors[si], boards[v]), b.grey_noise, b.depth_noise,
                                          b.seed * 1000003 + 1000 * si + v);
      write_view(dir / view_name(v), view, true);
      r.images += 2;
      ++seen;
    }
  }
  // What the robot reports: its true tool pose with an error (a robot's
  // absolute accuracy is millimetres, far worse than its repeatability).
  for (std::size_t v = 0; v < chosen.size(); ++v) {
    Eigen::Isometry3d reported = robot::forward(arm, chosen[v])[7];
    const Eigen::Vector3d axis = Eigen::Vector3d(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1)).normalized();
    reported.linear() = reported.linear() * Eigen::AngleAxisd(rng.gaussian(o.tool_noise_deg * M_PI / 180.0), axis).toRotationMatrix();
    reported.translation() += 1e-3 * o.tool_noise_mm * Eigen::Vector3d(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1));
    poses.base_from_tool[view_name(v)] = reported;
  }
  write_tool_poses((std::filesystem::path(b.dir) / "tool_poses.yaml").string(), poses,
                   "the simulated robot's tool poses (skelgraph sim boards --robot " + o.base_text + ")");
  write_calib_file((std::filesystem::path(b.dir) / "truth.yaml").string(),
                   true_poses(cfg, "the simulator's true sensor poses (skelgraph sim boards --robot)"));
  return r;
}

}  // namespace skelgraph::calib
