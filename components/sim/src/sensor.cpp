#include "skelgraph/sim/sensor.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace skelgraph::sim {

Eigen::Isometry3d SensorConfig::world_from_sensor() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  t.translation() = position;
  return t;
}

skeleton::SensorPose SensorConfig::true_pose(std::int64_t stamp_ns) const {
  skeleton::SensorPose p;
  p.sensor_id = id;
  p.pose = world_from_sensor();
  p.stamp_ns = stamp_ns;
  p.method = "ground_truth";
  return p;
}

std::vector<SensorConfig> default_sensors(int count, double distance) {
  if (count < 1 || count > 16) throw std::invalid_argument("sensor count must be 1-16");
  static const double offsets_ms[] = {0.0, 12.0, -7.0, 20.0};
  std::vector<SensorConfig> out;
  for (int i = 0; i < count; ++i) {
    SensorConfig c;
    c.id = "sensor" + std::to_string(i + 1);
    const double a = i * M_PI / 2.0 + (i / 4) * M_PI / 4.0;
    c.position = Eigen::Vector3d(distance * std::sin(a), 1.2, distance * std::cos(a));
    c.yaw = a + M_PI;
    c.clock_offset_s = offsets_ms[i % 4] * 1e-3;
    out.push_back(c);
  }
  return out;
}

const std::vector<std::string>& layout_names() {
  static const std::vector<std::string> names{"quarters", "ring", "one_side", "corners"};
  return names;
}

std::vector<SensorConfig> layout_sensors(const std::string& layout, int count, double distance) {
  if (layout == "quarters") return default_sensors(count, distance);
  if (count < 1 || count > 16) throw std::invalid_argument("sensor count must be 1-16");
  std::vector<double> angles;  // degrees round the cell from +z, towards +x
  if (layout == "ring") {
    for (int i = 0; i < count; ++i) angles.push_back(360.0 * i / count);
  } else if (layout == "one_side") {
    for (int i = 0; i < count; ++i) angles.push_back(count == 1 ? 0.0 : -45.0 + 90.0 * i / (count - 1));
  } else if (layout == "corners") {
    if (count != 4) throw std::invalid_argument("layout 'corners' has 4 sensors, not " + std::to_string(count));
    angles = {45.0, 135.0, 225.0, 315.0};
  } else {
    std::string all;
    for (const auto& n : layout_names()) all += (all.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown sensor layout '" + layout + "' (expected one of: " + all + ")");
  }
  auto out = default_sensors(count, distance);  // ids and clock offsets
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double a = angles[i] * M_PI / 180.0;
    out[i].position = Eigen::Vector3d(distance * std::sin(a), 1.2, distance * std::cos(a));
    out[i].yaw = a + M_PI;
  }
  return out;
}

SensorConfig parse_sensor(const std::string& spec, const SensorConfig& defaults) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("sensor '" + spec + "': " + why + " (expected id:x,y,z,yaw_deg[,pitch_deg])");
  };
  const auto colon = spec.find(':');
  if (colon == std::string::npos || colon == 0) throw bad("no 'id:' in front");
  SensorConfig c = defaults;
  c.id = spec.substr(0, colon);
  std::vector<double> v;
  std::stringstream ss(spec.substr(colon + 1));
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || item.find_first_not_of(" \t", used) != std::string::npos || !std::isfinite(x)) {
      throw bad("'" + item + "' is not a number");
    }
    v.push_back(x);
  }
  if (v.size() != 4 && v.size() != 5) throw bad(std::to_string(v.size()) + " numbers");
  c.position = Eigen::Vector3d(v[0], v[1], v[2]);
  c.yaw = v[3] * M_PI / 180.0;
  c.pitch = v.size() == 5 ? v[4] * M_PI / 180.0 : 0.0;
  return c;
}

SensorView::SensorView(const SensorConfig& c)
    : c_(c), sensor_from_world_(c.world_from_sensor().inverse()), origin_(c.position) {}

bool SensorView::in_view(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d p = to_sensor(world);
  if (p.z() < c_.min_range || p.z() > c_.max_range) return false;
  return std::abs(std::atan2(p.x(), p.z())) <= c_.hfov / 2 && std::abs(std::atan2(p.y(), p.z())) <= c_.vfov / 2;
}

bool SensorView::blocked(const Eigen::Vector3d& world, const std::vector<Obstacle>& obstacles,
                         double* hit_depth) const {
  const Eigen::Vector3d d = world - origin_;
  bool any = false;
  double nearest = 1.0;
  for (const auto& o : obstacles) {
    // Slab test on the segment origin -> world (parameter in [0, 1]).
    double t0 = 0.0, t1 = 1.0;
    bool hit = true;
    for (int k = 0; k < 3 && hit; ++k) {
      const double lo = o.box.min()[k], hi = o.box.max()[k];
      if (std::abs(d[k]) < 1e-12) {
        hit = origin_[k] >= lo && origin_[k] <= hi;
        continue;
      }
      double a = (lo - origin_[k]) / d[k], b = (hi - origin_[k]) / d[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
      hit = t0 <= t1;
    }
    // A point inside (or on the near face of) a box is hidden by it too.
    if (hit && t0 < 1.0) {
      any = true;
      nearest = std::min(nearest, t0);
    }
  }
  if (any && hit_depth != nullptr) *hit_depth = nearest * d.norm();
  return any;
}

double SensorView::view_angle(const BodyPose& pose) const {
  const Eigen::Vector2d facing(std::sin(pose.heading), std::cos(pose.heading));
  Eigen::Vector2d to_sensor(origin_.x() - pose.floor_position.x(), origin_.z() - pose.floor_position.y());
  if (to_sensor.norm() < 1e-9) return 0.0;
  to_sensor.normalize();
  return std::acos(std::clamp(facing.dot(to_sensor), -1.0, 1.0));
}

std::vector<double> frame_times(const SensorConfig& c, double duration, Rng& rng) {
  std::vector<double> out;
  const double period = 1.0 / c.rate_hz;
  const double phase = rng.uniform(0.0, period);  // sensors do not start together
  double last = -1.0;
  for (long k = 0;; ++k) {
    const double nominal = phase + static_cast<double>(k) * period;
    if (nominal >= duration) break;
    const double t = nominal + c.jitter_s * rng.normal();
    const bool dropped = rng.chance(c.drop_probability);
    if (dropped || t <= last || t < 0.0 || t >= duration) continue;
    out.push_back(t);
    last = t;
  }
  return out;
}

std::int64_t sensor_stamp_ns(const SensorConfig& c, double world_t, std::int64_t world_epoch_ns) {
  const double local = world_t * (1.0 + c.clock_drift_ppm * 1e-6) + c.clock_offset_s;
  return world_epoch_ns + static_cast<std::int64_t>(std::llround(local * 1e9));
}

}  // namespace skelgraph::sim
