#pragma once
// `depth_tracker` component: skeletons from depth. Subscribes skelgraph/depth
// (any number of sensors) and skelgraph/calibration (each sensor's pose: where
// the floor is), runs one DepthTracker per sensor and publishes its people on
// skelgraph/skeleton/raw (sensor frame, the image's stamp) plus a
// skelgraph/sensor/frame heartbeat per image, like any skeleton source.

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "skelgraph/depth_tracker/tracker.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::depth_tracker {

class DepthTrackerComponent final : public runtime::Component {
 public:
  DepthTrackerComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void on_depth(const msg::DepthFrame& frame);

  struct Sensor {
    DepthTracker tracker;
    bool posed = false;
    std::uint64_t frames = 0, skeletons = 0, skipped = 0;
    double track_s = 0.0;
  };
  TrackerOptions options_;
  bool assume_level_ = false;
  double sensor_height_ = 1.2;
  mutable std::mutex mutex_;
  std::map<std::string, Sensor> sensors_;
  std::map<std::string, Eigen::Isometry3d> poses_;
  runtime::Publisher<msg::Skeleton> raw_pub_;
  runtime::Publisher<msg::SensorFrame> frame_pub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Subscription<msg::DepthFrame> depth_sub_;
};

}  // namespace skelgraph::depth_tracker
