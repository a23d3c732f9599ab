#pragma once
// A depth/colour camera's pinhole intrinsics (OpenCV conventions: pixel
// centres at integers, x right, y down).

#include <vector>

#include <Eigen/Core>

namespace skelgraph::calib {

struct Intrinsics {
  int width = 640, height = 480;
  double fx = 525, fy = 525, cx = 319.5, cy = 239.5;  // Kinect-like defaults
  std::vector<double> distortion;  // OpenCV order k1 k2 p1 p2 k3; empty: none
  // (x, y, 1) of pixel (u, v), distortion ignored.
  Eigen::Vector3d ray(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }
};

}  // namespace skelgraph::calib
