#pragma once
// `sim` component: runs the virtual work cell in real time (or a multiple of
// it) and publishes ground truth on skelgraph/skeleton/truth (world frame),
// each virtual sensor's tracker output on skelgraph/skeleton/raw (sensor frame,
// sensor clock) and the sensors' true poses on skelgraph/calibration; with
// `depth`, also each sensor's depth image on skelgraph/depth (depth_render.hpp).

#include <atomic>
#include <map>
#include <memory>

#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/sim/depth_render.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::sim {

class SimComponent final : public runtime::Component {
 public:
  SimComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();

  void on_start() override;
  // Without `loop` the run has an end: the scenario's (a graph run stops once every such component is done).
  bool finite() const override { return !loop_; }
  bool finished() const override { return finished_; }
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void tick();
  void publish_poses();

  SimConfig config_;
  double rate_ = 1.0;
  bool loop_ = false;
  std::unique_ptr<Simulation> sim_;
  runtime::Publisher<msg::Skeleton> truth_pub_, raw_pub_;
  runtime::Publisher<msg::SensorFrame> frame_pub_;
  runtime::Publisher<msg::SensorPose> pose_pub_;
  std::unique_ptr<runtime::Publisher<msg::DepthFrame>> depth_pub_;  // with `depth`
  std::vector<DepthRenderer> renderers_;                             // per sensor, with `depth`
  std::vector<Rng> depth_rngs_;
  double girth_ = 1.1;
  runtime::TimerHandle timer_;
  std::int64_t start_mono_ns_ = 0;
  std::vector<std::string> publish_sensors_;  // empty: all
  bool publish_truth_ = true, publish_poses_ = true, publish_raw_ = true, aligned_ = false;
  void publish_depth(const SimEvent& frame);
  double skip_before_s_ = 0.0;  // aligned start: events before this were "published" before we started
  bool publishes(std::size_t sensor) const;
  double loop_offset_s_ = 0.0;  // world time at which the current run started
  std::uint64_t truth_published_ = 0, raw_published_ = 0, depth_published_ = 0, runs_completed_ = 0;
  std::uint64_t departures_ = 0, users_lost_ = 0;  // truth and raw instances disposed
  std::atomic<bool> finished_{false};
  // A robot's links (skelgraph/robot/state) hide people from the sensors (`robot_hides`).
  std::map<std::string, std::vector<Capsule>> robot_links_;  // per robot id
  std::vector<Capsule> all_robot_links() const;
  std::unique_ptr<runtime::Subscription<msg::RobotState>> robot_sub_;
};

// Builds the simulation's configuration from the component's parameters
// (also used by `skelgraph sim export`). Throws std::invalid_argument.
SimConfig sim_config_from(const runtime::Params& params);
// The parameters both take.
void add_sim_params(runtime::ParamSchema& schema);
// The configuration from KEY=VALUE assignments (`--param`), then `extra`
// (e.g. {"scenario", "walk", ...}), checked by building a simulation. Every
// offline command that simulates uses it. Throws runtime::ParamError (naming
// `what`) or std::invalid_argument.
SimConfig sim_config_from_assignments(const std::vector<std::string>& assignments, const std::string& what,
                                      const std::vector<runtime::RawParam>& extra = {});

}  // namespace skelgraph::sim
