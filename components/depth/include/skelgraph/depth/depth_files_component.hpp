#pragma once
// `depth_files` component: a folder of depth image files (depth_files.hpp)
// played on skelgraph/depth exactly as the openni2 source publishes a
// device's, stamped with the playback clock and paced by the files' times;
// a player on skelgraph/play/control (pause, resume, step, speed, seek).

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "skelgraph/depth/depth_files.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/player_link.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::depth {

class DepthFilesComponent final : public runtime::Component {
 public:
  DepthFilesComponent(runtime::Context& ctx, const runtime::Params& params);
  ~DepthFilesComponent() override;
  static runtime::ComponentInfo describe();
  void on_start() override;
  void on_shutdown() override;
  bool finite() const override { return !loop_ && !hold_at_end_; }
  bool finished() const override { return finished_; }
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void run();

  std::unique_ptr<DepthFolder> folder_;
  bool loop_ = false, hold_at_end_ = false;
  double wait_s_ = 5.0;
  std::atomic<bool> finished_{false}, stop_{false};
  std::thread thread_;
  runtime::Publisher<msg::DepthFrame> depth_pub_;
  std::unique_ptr<runtime::PlayerLink> player_;
  mutable std::mutex mutex_;  // guards what follows
  std::uint64_t published_ = 0, loops_ = 0;
  std::size_t position_ = 0;  // the next image
  std::string error_;
};

}  // namespace skelgraph::depth
