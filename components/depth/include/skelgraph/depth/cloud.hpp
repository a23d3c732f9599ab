#pragma once
// Point clouds from depth images: back-projection, a per-pixel background
// model, person segmentation (connected foreground regions), voxel
// down-sampling, and clouds of several calibrated sensors merged in the world
// frame. DDS-free.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "skelgraph/depth/depth_image.hpp"

namespace skelgraph::depth {

using Points = std::vector<Eigen::Vector3f>;

// Every `stride`-th pixel in both directions with a reading in (0, max_depth_m],
// as sensor-frame points.
Points to_points(const DepthImage& image, int stride = 1, double max_depth_m = 10.0);
// The same for the pixels where mask is non-zero (mask: width * height).
Points to_points(const DepthImage& image, const std::vector<std::uint8_t>& mask, int stride = 1);

// One point per occupied cube of side `voxel_m` (the mean of its points), in
// the order the cubes were first met.
Points voxel_downsample(const Points& points, double voxel_m);

Points transformed(const Points& points, const Eigen::Isometry3d& pose);

// The static scene as each pixel has seen it. A pixel's background is the
// farthest depth it has reported steadily (a person walking by reveals what
// is behind); a reading clearly nearer than it is foreground. The margin grows
// with the square of depth like the sensor's noise.
class BackgroundModel {
 public:
  struct Options {
    double margin_m = 0.06;        // foreground if nearer than background - margin (at 1 m) ...
    double margin_per_m2 = 0.01;   // ... plus this times depth^2
    int frames_to_learn = 15;      // frames before foreground() is trusted
  };
  BackgroundModel() : BackgroundModel(Options{}) {}
  explicit BackgroundModel(Options options);

  // Takes the image into the model (the first image fixes the size; a later
  // image of another size throws std::invalid_argument).
  void learn(const DepthImage& image);
  bool ready() const { return frames_ >= opt_.frames_to_learn; }
  int frames() const { return frames_; }
  // 1 where the image has a reading clearly nearer than the background (or the
  // background has never had one), else 0.
  std::vector<std::uint8_t> foreground(const DepthImage& image) const;
  const std::vector<std::uint16_t>& background_mm() const { return background_; }

 private:
  Options opt_;
  int width_ = 0, height_ = 0, frames_ = 0;
  std::vector<std::uint16_t> background_;
  std::vector<std::uint16_t> candidate_;  // a farther reading waiting to be confirmed
  std::vector<std::uint8_t> seen_;        // how often the candidate was seen
};

// Connected regions of a foreground mask: 4-neighbours join when their depths
// differ by at most `max_step_m`; regions under `min_pixels` are dropped.
struct Region {
  std::uint32_t label = 0;   // in Segmentation::labels
  std::size_t pixels = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // sensor frame, m
  Eigen::AlignedBox3d bounds;                          // sensor frame, m
};
struct Segmentation {
  std::vector<std::uint32_t> labels;  // width * height; 0 = none
  std::vector<Region> regions;        // largest first
};
Segmentation segment(const DepthImage& image, const std::vector<std::uint8_t>& mask, double max_step_m = 0.08,
                     std::size_t min_pixels = 200);

// Clouds of several sensors in one frame: each sensor's points moved by its
// pose (frame <- sensor), then down-sampled together.
struct SensorCloud {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Points points;  // sensor frame
};
Points merge_clouds(const std::vector<SensorCloud>& clouds, double voxel_m);

}  // namespace skelgraph::depth
