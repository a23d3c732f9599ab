#pragma once
// Checkerboard calibration: corners found in images, intrinsics by
// calibrateCamera, corners lifted to 3-D with a depth image, board views read
// from and written to PNG files, and synthetic board views (colour and depth)
// rendered with known intrinsics and pose for tests and `skelgraph sim
// boards`. OpenCV does the work inside; its types stay out of this header
// (images are skelgraph's GreyImage and DepthImageMm, corners Eigen points).
//
// Frames: image and camera coordinates are OpenCV's (x right, y down, z
// forward). skelgraph's sensor frames are the skeleton trackers' (x left,
// y up, z forward): sensor_from_camera() converts.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

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

// Images row by row, (0, 0) top left.
struct GreyImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;
};
struct DepthImageMm {
  int width = 0, height = 0;
  std::vector<std::uint16_t> mm;  // 0: no reading
};
// Image corners, pixels (OpenCV's sub-pixel positions, single precision as it finds them).
using Corners = std::vector<Eigen::Vector2f>;

// PNG files (any image OpenCV reads, as 8-bit grey; a 16-bit single-channel
// one for depth). Throw CalibError naming the file and what was wrong.
GreyImage read_grey_image(const std::string& path);
DepthImageMm read_depth_image(const std::string& path);
void write_png(const std::string& path, const GreyImage& image);
void write_png(const std::string& path, const DepthImageMm& image);

// The board's inner corners in an 8-bit grey image, refined to sub-pixel and
// put in one order whichever way the board is turned (the square between
// the first four corners is the dark one); empty if the board is not found.
std::optional<Corners> find_corners(const GreyImage& grey, const Board& board);

struct IntrinsicsResult {
  Intrinsics intrinsics;
  double rms_reprojection_px = 0;
  std::size_t views = 0;
};
// calibrateCamera over the views' corners; throws CalibError with fewer than 3 views.
IntrinsicsResult calibrate_intrinsics(const std::vector<Corners>& corners, const Board& board, int width, int height);

struct LiftedCorners {
  std::vector<Eigen::Vector3d> points;  // camera frame, m, same order as the corners
  double plane_rms_m = 0;                // depth pixels' spread about the board plane
  std::size_t depth_pixels = 0;
};
// A plane fitted (robustly) to the depth pixels inside the corners' outline,
// each corner's ray cut with it. Throws CalibError when the board has too
// few depth readings.
LiftedCorners lift_corners(const Corners& corners, const DepthImageMm& depth, const Intrinsics& k, const Board& board);

// Board views in a directory: NAME_color.png with NAME_depth.png (16-bit mm,
// registered to the colour image), by name.
std::vector<std::string> board_view_names(const std::string& dir);  // throws CalibError when unreadable
// One view NAME in DIR: the board's corners found in NAME_color.png and
// lifted to 3-D (camera frame) with NAME_depth.png; nothing, with the reason
// in `why`, when the view is missing or the board is not usable in it.
// Throws CalibError for an image that cannot be read.
std::optional<std::vector<Eigen::Vector3d>> lift_board_view(const std::string& dir, const std::string& name,
                                                            const Board& board, const Intrinsics& k, std::string* why);

// A synthetic view: the board at camera_from_board, grey image (noise sd in
// grey levels) and depth in mm (Kinect-like noise growing with distance
// squared, quantised to 1 mm; 0 off the board).
struct BoardView {
  GreyImage grey;
  DepthImageMm depth_mm;
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
