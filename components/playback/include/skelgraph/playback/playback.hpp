#pragma once
// `playback` component: replays recorded data sets on skelgraph/skeleton/raw
// as a live sensor would (recorded rate, a multiple of it, or as fast as possible).

#include <memory>
#include <string>

#include "skelgraph/playback/readers.hpp"
#include "skelgraph/playback/schedule.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::playback {

class Playback final : public runtime::Component {
 public:
  Playback(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();

  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  void tick();

  std::vector<std::string> files_;
  ReadReport report_;  // summed over files
  std::unique_ptr<PlaybackSchedule> schedule_;
  runtime::Publisher<msg::Skeleton> pub_;
  runtime::TimerHandle timer_;
  std::int64_t start_mono_ns_ = 0;
  std::int64_t gone_after_ns_ = 1'000'000'000;
  std::int64_t start_stamp_ns_ = 0;
};

}  // namespace skelgraph::playback
