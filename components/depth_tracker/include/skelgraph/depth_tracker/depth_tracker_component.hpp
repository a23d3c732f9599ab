#pragma once
// `depth_tracker` component: skeletons from depth. Subscribes skelgraph/depth
// (any number of sensors) and skelgraph/calibration (each sensor's pose: where
// the floor is), runs one DepthTracker per sensor and publishes its people on
// skelgraph/skeleton/raw (sensor frame, the image's stamp) plus a
// skelgraph/sensor/frame heartbeat per image, like any skeleton source.
// With `merge`, one tracker fits every calibrated sensor's points at once
// (DepthTracker::track_merged) on each image of the first sensor seen, with
// the others' latest images of the same moment, and publishes its skeletons
// as sensor `merged_id` in the world frame (its pose, the identity, goes on
// skelgraph/calibration so fusion places it).

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "skelgraph/depth_tracker/frame_matcher.hpp"
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
  void on_depth_merged(depth::DepthImage image, std::int64_t receive_ns);
  void dispose(const std::string& sensor, const std::vector<std::uint32_t>& people);

  struct Sensor {
    DepthTracker tracker;
    bool posed = false;
    std::uint64_t frames = 0, skeletons = 0, skipped = 0;
    double track_s = 0.0;
  };
  TrackerOptions options_;
  bool merge_ = false;
  std::string merged_id_;
  FrameMatcher<std::string> moments_;  // merge: the first sensor's images trigger a fit, with the others' of that moment
  std::unique_ptr<DepthTracker> merged_;
  std::uint64_t merged_fits_ = 0, merged_skeletons_ = 0;
  double merged_s_ = 0.0;
  bool assume_level_ = false;
  double sensor_height_ = 1.2;
  mutable std::mutex mutex_;
  std::map<std::string, Sensor> sensors_;
  std::map<std::string, Eigen::Isometry3d> poses_;
  runtime::Publisher<msg::Skeleton> raw_pub_;
  runtime::Publisher<msg::SensorFrame> frame_pub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Publisher<msg::SensorPose> pose_pub_;
  runtime::Subscription<msg::DepthFrame> depth_sub_;
};

}  // namespace skelgraph::depth_tracker
