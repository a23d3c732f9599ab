#pragma once
// Checkerboard calibration (OpenCV): corners found in images, intrinsics by
// calibrateCamera, corners lifted to 3-D with a depth image, and synthetic
// board views (colour and depth) rendered with known intrinsics and pose for
// tests and `skelgraph sim boards`.
//
// Frames: image and camera coordinates are OpenCV's (x right, y down, z
// forward). skelgraph's sensor frames are the skeleton trackers' (x left,
// y up, z forward): sensor_from_camera() converts.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "skelgraph/calib/intrinsics.hpp"
#include "skelgraph/calib/rigid.hpp"

namespace skelgraph::calib {

struct Board {
  int cols = 9, rows = 6;  // inner corners
  double square_m = 0.08;
  // "9x6" -> cols 9, rows 6; throws CalibError otherwise.
  static Board parse(const std::string& size, double square_m);
  // Inner corners in the board frame (z = 0), row by row, as findChessboardCorners orders them.
  std::vector<Eigen::Vector3d> object_points() const;
};

cv::Mat camera_matrix(const Intrinsics& k);

// The board's inner corners in an 8-bit grey image, refined to sub-pixel and
// put in one order whichever way the board is turned (the square between
// the first four corners is the dark one); empty if the board is not found.
std::optional<std::vector<cv::Point2f>> find_corners(const cv::Mat& grey, const Board& board);

struct IntrinsicsResult {
  Intrinsics intrinsics;
  double rms_reprojection_px = 0;
  std::size_t views = 0;
};
// calibrateCamera over the views' corners; throws CalibError with fewer than 3 views.
IntrinsicsResult calibrate_intrinsics(const std::vector<std::vector<cv::Point2f>>& corners, const Board& board,
                                      cv::Size image_size);

struct LiftedCorners {
  std::vector<Eigen::Vector3d> points;  // camera frame, m, same order as the corners
  double plane_rms_m = 0;                // depth pixels' spread about the board plane
  std::size_t depth_pixels = 0;
};
// A plane fitted (robustly) to the depth pixels inside the corners' outline,
// each corner's ray cut with it. `depth_mm`: CV_16U millimetres, 0 = no
// reading. Throws CalibError when the board has too few depth readings.
LiftedCorners lift_corners(const std::vector<cv::Point2f>& corners, const cv::Mat& depth_mm, const Intrinsics& k,
                           const Board& board);

// A synthetic view: the board at camera_from_board, grey image (noise sd in
// grey levels) and depth in mm (Kinect-like noise growing with distance
// squared, quantised to 1 mm; 0 off the board).
struct BoardView {
  cv::Mat grey, depth_mm;
};
BoardView render_board_view(const Board& board, const Intrinsics& k, const Eigen::Isometry3d& camera_from_board,
                            double grey_noise, double depth_noise_scale, std::uint64_t seed);

// Board poses (world_from_board) that every given sensor (world_from_sensor,
// skelgraph sensor frames) sees whole, 0.8-3 m away and facing them within
// 45 degrees: the board held up around `centre`, turned towards the sensors.
std::vector<Eigen::Isometry3d> board_poses_seen_by(const std::vector<Eigen::Isometry3d>& world_from_sensors,
                                                   const Board& board, const Intrinsics& k, int count,
                                                   const Eigen::Vector3d& centre, std::uint64_t seed);

// Whether a sensor (world_from_sensor) sees the whole board
// (world_from_board) well enough to calibrate from: every corner in the
// image 20 px from its edge, 0.8-3 m away, the printed side facing it within
// 45 degrees. Nothing between them is modelled.
bool board_in_view(const Eigen::Isometry3d& world_from_sensor, const Eigen::Isometry3d& world_from_board,
                   const Board& board, const Intrinsics& k);

// camera_from_board for a sensor at world_from_sensor.
Eigen::Isometry3d camera_from_board(const Eigen::Isometry3d& world_from_sensor, const Eigen::Isometry3d& world_from_board);


}  // namespace skelgraph::calib
