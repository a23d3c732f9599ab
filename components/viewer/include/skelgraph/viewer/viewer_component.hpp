#pragma once
// `viewer` component: a live 3-D view of the cell in the browser. Subscribes to
// skeletons (raw, fused, truth), sensor poses, gesture events, component status
// and players' state; keeps them in a Scene; broadcasts a frame to every page
// `rate_hz` times a second over a WebSocket (Server). Pages may drive players
// of recordings (PlayControl). See components/viewer/README.md.

#include <atomic>
#include <memory>
#include <string>

#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/executor.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/viewer/scene.hpp"
#include "skelgraph/viewer/server.hpp"

namespace skelgraph::viewer {

class ViewerComponent final : public runtime::Component {
 public:
  ViewerComponent(runtime::Context& ctx, const runtime::Params& params);
  ~ViewerComponent() override;
  static runtime::ComponentInfo describe();
  void on_start() override;
  void on_shutdown() override;
  std::string summary() const override;
  nlohmann::json details() const override;

  std::string url() const;

 private:
  void on_skeleton(const msg::Skeleton& m, std::int64_t now_ns);
  void on_gone(const msg::Skeleton& last);
  std::int64_t now_mono() const { return ctx_.clock().monotonic_ns(); }  // the scene's time
  std::string on_client_message(const std::string& text, bool& bad);

  Scene scene_;
  std::string address_;
  bool secure_ = false;  // HTTPS/WSS with credentials
  std::int64_t period_ns_;
  std::unique_ptr<Server> server_;
  std::atomic<std::uint64_t> frames_made_{0}, play_requests_{0};
  runtime::Publisher<msg::PlayControl> play_pub_;
  runtime::Subscription<msg::Skeleton> raw_sub_, fused_sub_, truth_sub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Subscription<msg::GestureEvent> gesture_sub_;
  runtime::Subscription<msg::ComponentStatus> status_sub_;
  runtime::Subscription<msg::PlayState> play_state_sub_;
  runtime::Subscription<msg::RobotState> robot_sub_;
  runtime::Subscription<msg::SafetyStatus> safety_sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::viewer
