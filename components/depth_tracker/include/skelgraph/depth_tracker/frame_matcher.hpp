#pragma once
// The depth images of one moment across sensors, for one model fitted to
// every sensor's points at once (DepthTracker::track_merged). Each sensor's
// latest image is kept; a frame of the lead sensor (the first one added,
// unless given) comes out with every sensor's latest taken within `window_ns`
// of it, its own included, in the order of the sensors' ids. The one way of
// matching frames: live (the depth_tracker component, on receive times) and
// offline (track_simulated_depth, on the simulator's clock). No DDS.

#include <cstdint>
#include <cstdlib>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "skelgraph/depth/depth_image.hpp"

namespace skelgraph::depth_tracker {

template <class SensorId>
class FrameMatcher {
 public:
  struct View {
    SensorId sensor;
    const depth::DepthImage* image;  // valid until the next add()
  };

  explicit FrameMatcher(std::int64_t window_ns = 40'000'000, std::optional<SensorId> lead = std::nullopt)
      : window_ns_(window_ns), lead_(std::move(lead)) {}

  // Keeps the image as its sensor's latest. For the lead's frame, returns the
  // moment's views; for another sensor's, nothing. (The id by value and the
  // image by reference: `add(image.sensor_id, t, std::move(image))` is safe.)
  std::vector<View> add(SensorId sensor, std::int64_t t_ns, depth::DepthImage&& image) {
    if (!lead_) lead_ = sensor;
    latest_[sensor] = {t_ns, std::move(image)};
    std::vector<View> views;
    if (!(sensor == *lead_)) return views;
    for (const auto& [id, entry] : latest_) {
      if (std::llabs(entry.first - t_ns) > window_ns_) continue;  // not a frame of this moment
      views.push_back({id, &entry.second});
    }
    return views;
  }

  const std::optional<SensorId>& lead() const { return lead_; }

 private:
  std::int64_t window_ns_;
  std::optional<SensorId> lead_;
  std::map<SensorId, std::pair<std::int64_t, depth::DepthImage>> latest_;
};

}  // namespace skelgraph::depth_tracker
