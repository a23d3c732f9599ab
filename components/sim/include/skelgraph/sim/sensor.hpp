#pragma once
// Virtual depth sensors: where they are, what they can see, and when they
// deliver frames. DDS-free.
//
// Sensor frame (as the Kinect SDK and OpenNI report skeletons): metres, z along
// the optical axis away from the sensor, y up, x to the sensor's left.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/sim/rng.hpp"
#include "skelgraph/sim/scenario.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::sim {

struct SensorConfig {
  std::string id = "sensor1";
  Eigen::Vector3d position{0.0, 1.2, 2.0};  // world, m
  double yaw = M_PI;      // rad about world +y; 0 looks along +z
  double pitch = 0.0;     // rad, positive tilts the view down
  double min_range = 0.8, max_range = 4.0;        // m along the optical axis
  double hfov = 57.0 * M_PI / 180.0, vfov = 43.0 * M_PI / 180.0;
  double rate_hz = 30.0;
  double jitter_s = 0.002;     // sd of each frame's capture time around the nominal
  double drop_probability = 0.01;
  double clock_offset_s = 0.0;  // the sensor host's clock minus the world clock
  double clock_drift_ppm = 0.0;

  Eigen::Isometry3d world_from_sensor() const;
  // Its true pose as a calibration says it (method ground_truth), stamped `stamp_ns`.
  skeleton::SensorPose true_pose(std::int64_t stamp_ns = 0) const;
};

// `count` sensors 90 degrees apart around the cell centre, `distance` m from
// it, 1.2 m high, looking at it: sensor1 on +z, sensor2 on +x, ... Each has its
// own clock offset (0, +12, -7, +20 ms, ...).
std::vector<SensorConfig> default_sensors(int count = 2, double distance = 2.0);

// Sensor layouts of a cell, `count` sensors `distance` m from its centre,
// 1.2 m high, each looking at it (sensor1 on +z, facing the first person):
//   quarters  default_sensors: 90 degrees apart (the thesis's pair), then the 45-degree places between
//   ring      evenly round the cell, 360/count degrees apart
//   one_side  over the quarter circle in front of the person (from -45 to +45 degrees)
//   corners   the four corners of the cell (count must be 4): at 45, 135, 225, 315 degrees
// Throws std::invalid_argument for an unknown name or a count it cannot take.
std::vector<SensorConfig> layout_sensors(const std::string& layout, int count, double distance = 2.0);
const std::vector<std::string>& layout_names();

// "id:x,y,z,yaw_deg[,pitch_deg]" (yaw 180 looks along -z). Throws
// std::invalid_argument naming what is wrong.
SensorConfig parse_sensor(const std::string& spec, const SensorConfig& defaults = {});

class SensorView {
 public:
  explicit SensorView(const SensorConfig& c);
  const SensorConfig& config() const { return c_; }
  const Eigen::Isometry3d& sensor_from_world() const { return sensor_from_world_; }
  Eigen::Vector3d to_sensor(const Eigen::Vector3d& world) const { return sensor_from_world_ * world; }

  // In range and inside the field of view.
  bool in_view(const Eigen::Vector3d& world) const;
  // The line of sight to `world` passes through an obstacle; `hit_depth`
  // (optional) gets the distance from the sensor to where it first does.
  bool blocked(const Eigen::Vector3d& world, const std::vector<Obstacle>& obstacles, double* hit_depth = nullptr) const;
  // Angle between the direction a person faces and the direction from them to
  // the sensor, in [0, pi]: 0 facing the sensor, pi the back to it.
  double view_angle(const BodyPose& pose) const;

 private:
  SensorConfig c_;
  Eigen::Isometry3d sensor_from_world_;
  Eigen::Vector3d origin_;
};

// Frame capture times (world clock, s) of a sensor over [0, duration): nominal
// period, Gaussian jitter, independent drops. Deterministic for a given rng.
std::vector<double> frame_times(const SensorConfig& c, double duration, Rng& rng);

// The sensor clock's reading (ns) at world time t.
std::int64_t sensor_stamp_ns(const SensorConfig& c, double world_t, std::int64_t world_epoch_ns);

}  // namespace skelgraph::sim
