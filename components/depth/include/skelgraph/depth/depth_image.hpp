#pragma once
// A depth image and its camera, as OpenNI2 and the simulator deliver them:
// uint16 millimetres along the optical axis (0 = no reading), row-major,
// pinhole intrinsics. DDS-free; the wire type is msg::DepthFrame (depth_msg.hpp).
//
// Pixels and the sensor frame: the sensor frame is the one skeletons are
// reported in (metres, z along the optical axis, y up, x to the sensor's
// left); image u grows to the right and v downwards, so
//   u = cx - fx * x / z,   v = cy - fy * y / z.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/calib/intrinsics.hpp"

namespace skelgraph::depth {

struct DepthImage {
  std::string sensor_id;
  std::int64_t stamp_ns = 0;
  std::uint64_t frame_number = 0;
  calib::Intrinsics intrinsics;   // width and height are the image's
  std::vector<std::uint16_t> mm;  // width * height, row-major; 0 = no reading

  int width() const { return intrinsics.width; }
  int height() const { return intrinsics.height; }
  // An image of the intrinsics' size with no readings.
  static DepthImage blank(const calib::Intrinsics& k);
  std::uint16_t at(int u, int v) const { return mm[static_cast<std::size_t>(v) * intrinsics.width + u]; }
  // Pixels with a reading.
  std::size_t valid_count() const;
};

// Kinect-like depth-camera intrinsics for a width x height image: fx = fy =
// 580 at 640 x 480 (the IR camera's; a 57.8 x 45 degree field of view), scaled
// for other sizes of the same aspect.
calib::Intrinsics kinect_intrinsics(int width = 640, int height = 480);
// "WxH" (160x120, 320x240 or 640x480) -> kinect_intrinsics of that size; throws std::invalid_argument naming the accepted sizes.
calib::Intrinsics parse_depth_size(const std::string& size);
// Intrinsics from fields of view (OpenNI2 reports only these), pixel centre at the middle.
calib::Intrinsics intrinsics_from_fov(int width, int height, double hfov_rad, double vfov_rad);

// The point in the sensor frame at pixel (u, v) with depth z metres.
inline Eigen::Vector3d unproject(const calib::Intrinsics& k, double u, double v, double z) {
  return {-(u - k.cx) / k.fx * z, -(v - k.cy) / k.fy * z, z};
}
// Pixel of a sensor-frame point (z must be > 0).
inline Eigen::Vector2d project(const calib::Intrinsics& k, const Eigen::Vector3d& p) {
  return {k.cx - k.fx * p.x() / p.z(), k.cy - k.fy * p.y() / p.z()};
}

// Throws std::invalid_argument naming what is wrong: size not positive, data
// not width*height, focal lengths not positive.
void check(const DepthImage& image);

}  // namespace skelgraph::depth
