#pragma once
// `openni2` component: an OpenNI2 depth device or .oni recording (oni_source.hpp)
// published on skelgraph/depth at the device's rate, from a capture thread of
// its own. With `record_directory` set, each sync session (START .. STOP on
// skelgraph/sync) is also recorded to an .oni file there, as the thesis's
// capture clients did. A recording is a player: paused, resumed, stepped
// and sped up by requests on skelgraph/play/control (`skelgraph play`), its
// state on skelgraph/play/state.

#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "skelgraph/openni2/oni_source.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/player_link.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::openni2 {

class OpenNI2Component final : public runtime::Component {
 public:
  OpenNI2Component(runtime::Context& ctx, const runtime::Params& params);
  ~OpenNI2Component() override;
  static runtime::ComponentInfo describe();

  void on_start() override;
  void on_shutdown() override;
  bool finite() const override { return finite_; }
  bool finished() const override { return finished_; }
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void run();
  void on_sync(const msg::SyncCommand& cmd, bool session_topic);
  // The player's state, answering `request_id` (with `error` when refused).

  OniOptions options_;
  std::string record_dir_;
  std::unique_ptr<OniSource> source_;  // opened in the constructor (errors before the graph starts), used by the thread
  bool finite_ = false;
  std::atomic<bool> finished_{false}, stop_{false};
  std::thread thread_;
  runtime::Publisher<msg::DepthFrame> depth_pub_;
  std::unique_ptr<runtime::Subscription<msg::SyncCommand>> sync_sub_, session_sub_;
  std::unique_ptr<runtime::PlayerLink> player_;  // recordings only: pause, step, speed; state

  mutable std::mutex mutex_;  // guards what follows
  std::optional<std::uint32_t> want_session_;  // a session to record (set by START, cleared by STOP)
  std::uint32_t recording_session_ = 0;        // what the thread records now (0: nothing)
  std::uint32_t last_stopped_ = 0;
  std::vector<std::string> files_;             // finished recordings
  std::uint64_t published_ = 0, files_frames_ = 0;
  std::string description_, error_;
};

}  // namespace skelgraph::openni2
