#pragma once
// `cloud` component: point clouds for viewers. Subscribes skelgraph/depth and
// each sensor's pose on skelgraph/calibration; at `rate_hz` publishes on
// skelgraph/cloud the chosen points of every sensor with a recent image —
// the people (person-shaped regions above the floor, found as the depth
// tracker finds them), the foreground (what differs from a background model
// learnt per sensor) or everything above the floor — moved into the world
// frame, merged and thinned to one point per `voxel_m` cube ("merged"), or
// each sensor's own (`merge: false`).

#include <map>
#include <mutex>
#include <string>

#include "skelgraph/depth/cloud.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::depth {

class CloudComponent final : public runtime::Component {
 public:
  CloudComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void on_depth(const msg::DepthFrame& frame, std::int64_t receive_ns);
  void publish();

  struct Sensor {
    BackgroundModel background;
    Points world;  // latest foreground, world frame (sensor frame without a pose)
    std::int64_t stamp_ns = 0, received_ns = 0;
    std::uint64_t frame_number = 0, images = 0;
    bool posed = false;
  };
  double voxel_m_, period_s_, floor_margin_m_;
  int stride_;
  bool merge_;
  std::string select_;
  mutable std::mutex mutex_;
  std::map<std::string, Sensor> sensors_;
  std::map<std::string, Eigen::Isometry3d> poses_;
  std::uint64_t published_ = 0, last_points_ = 0;
  runtime::Publisher<msg::PointCloud> pub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Subscription<msg::DepthFrame> depth_sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::depth
