#pragma once
// The whole virtual work cell: a scenario, its people, N sensors each with a
// tracker model. Produces, in time order, ground truth (world frame, world
// clock) and what each sensor's tracker reports (sensor frame, sensor clock).
// Deterministic: the same configuration and seed give bit-identical output.
// DDS-free; the `sim` component and the offline tools drive it.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "skelgraph/sim/scenario.hpp"
#include "skelgraph/sim/sensor.hpp"
#include "skelgraph/sim/tracker.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::sim {

struct SimConfig {
  ScenarioOptions scenario;
  std::vector<SensorConfig> sensors = default_sensors(2);
  std::string profile = "nite";
  double noise_scale = 1.0;
  double truth_rate_hz = 30.0;
  std::int64_t epoch_ns = 0;     // world clock at t = 0
  bool emit_frames = false;      // also a Frame event for every sensor frame (seen anyone or not)
  bool emit_departures = false;  // also Lost and Left events (when a tracker drops a user, a person leaves)
  // A sensor knocked out of place during the run (someone bumps it): from
  // world time at_s on it is turned by yaw_deg about the vertical through it
  // and moved shift_m to its own left; the poses in `sensors` (and those the
  // sim component publishes) stay as they were.
  struct Bump {
    std::string sensor;
    double at_s = 0, yaw_deg = 0, shift_m = 0;
  };
  std::vector<Bump> bumps;
};

// "SENSOR,AT_S,YAW_DEG,SHIFT_M" (e.g. "sensor2,60,3,0"); throws
// std::invalid_argument naming what is wrong.
SimConfig::Bump parse_bump(const std::string& spec);

struct SimEvent {
  // Lost: sensor's tracker no longer reports user skeleton.person_id (at this
  // frame of it; before its Raw events). Left: the person skeleton.person_id
  // is no longer in the scene (truth; before this truth frame's events).
  enum class Kind { Truth, Raw, Frame, Lost, Left };
  Kind kind = Kind::Truth;
  double t = 0.0;                  // world time, s since the start
  std::size_t sensor = 0;          // Raw: index into the configuration's sensors
  std::uint32_t actor = 0;         // the true person (Scene actor person_id)
  skeleton::Skeleton skeleton;     // Truth: world frame; Raw: sensor frame, stamped on the sensor clock;
                                   // Frame: only sensor_id, stamp_ns and frame_number
  std::uint32_t people = 0;        // Frame: skeletons the sensor reported in it
};

class Simulation {
 public:
  explicit Simulation(SimConfig config);  // throws std::invalid_argument on a bad configuration
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  const SimConfig& config() const { return cfg_; }
  const Scenario& scenario() const { return scenario_; }
  double duration() const { return scenario_.duration(); }
  // Events with world time < t, not yet returned, in time order.
  std::vector<SimEvent> advance(double t);
  bool finished() const;
  // Frames sensor i delivers over the whole run (dropped ones excluded), whether or not its tracker reports anyone.
  std::size_t frame_count(std::size_t sensor) const;
  // Ground truth of every person at world time t.
  std::vector<skeleton::Skeleton> truth_at(double t) const;
  // What else hides people from the sensors from now on (a robot's links,
  // world frame; Scene::occluders): the sensors' frames after this see them.
  void set_occluders(std::vector<Capsule> occluders) { occluders_ = std::move(occluders); }

 private:
  struct SensorState;
  void emit_truth(double t, std::vector<SimEvent>& out);
  void emit_raw(std::size_t sensor, double t, std::vector<SimEvent>& out);

  SimConfig cfg_;
  Scenario scenario_;
  BodyDimensions body_;
  std::vector<std::unique_ptr<SensorState>> sensors_;
  std::uint64_t truth_frame_ = 0;
  std::vector<std::uint32_t> truth_present_;  // people in the last truth frame (emit_departures)
  std::vector<Capsule> occluders_;
};

}  // namespace skelgraph::sim
