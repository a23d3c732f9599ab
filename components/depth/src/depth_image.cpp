#include "skelgraph/depth/depth_image.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

namespace skelgraph::depth {

DepthImage DepthImage::blank(const calib::Intrinsics& k) {
  DepthImage d;
  d.intrinsics = k;
  d.mm.assign(static_cast<std::size_t>(std::max(k.width, 0)) * static_cast<std::size_t>(std::max(k.height, 0)), 0);
  return d;
}

std::size_t DepthImage::valid_count() const {
  return static_cast<std::size_t>(std::count_if(mm.begin(), mm.end(), [](std::uint16_t v) { return v != 0; }));
}

calib::Intrinsics kinect_intrinsics(int width, int height) {
  calib::Intrinsics k;
  k.width = width;
  k.height = height;
  const double s = static_cast<double>(width) / 640.0;
  k.fx = k.fy = 580.0 * s;
  k.cx = (width - 1) / 2.0;
  k.cy = (height - 1) / 2.0;
  return k;
}

calib::Intrinsics parse_depth_size(const std::string& size) {
  for (const auto& [name, w, h] : {std::tuple{"160x120", 160, 120}, {"320x240", 320, 240}, {"640x480", 640, 480}}) {
    if (size == name) return kinect_intrinsics(w, h);
  }
  throw std::invalid_argument("depth_size '" + size + "': expected 160x120, 320x240 or 640x480");
}

calib::Intrinsics intrinsics_from_fov(int width, int height, double hfov_rad, double vfov_rad) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("intrinsics: image size must be positive");
  if (!(hfov_rad > 0 && hfov_rad < M_PI) || !(vfov_rad > 0 && vfov_rad < M_PI)) {
    throw std::invalid_argument("intrinsics: fields of view must be in (0, 180) degrees");
  }
  calib::Intrinsics k;
  k.width = width;
  k.height = height;
  k.fx = width / (2.0 * std::tan(hfov_rad / 2.0));
  k.fy = height / (2.0 * std::tan(vfov_rad / 2.0));
  k.cx = (width - 1) / 2.0;
  k.cy = (height - 1) / 2.0;
  return k;
}

void check(const DepthImage& image) {
  const auto& k = image.intrinsics;
  if (k.width <= 0 || k.height <= 0) {
    throw std::invalid_argument("depth image '" + image.sensor_id + "': size " + std::to_string(k.width) + "x" +
                                std::to_string(k.height) + " is not positive");
  }
  const auto want = static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height);
  if (image.mm.size() != want) {
    throw std::invalid_argument("depth image '" + image.sensor_id + "': " + std::to_string(image.mm.size()) +
                                " pixels, expected " + std::to_string(k.width) + "x" + std::to_string(k.height) +
                                " = " + std::to_string(want));
  }
  if (!(k.fx > 0) || !(k.fy > 0)) {
    throw std::invalid_argument("depth image '" + image.sensor_id + "': focal lengths must be positive");
  }
}

}  // namespace skelgraph::depth
