#pragma once
// `bag_player` component: republishes a recording's messages with their
// original timing (log time; a multiple of it with `rate`), topics and keys,
// exactly as recorded (CDR as it was sent). Component status is not replayed
// (it would describe components that are not running).

#include <memory>
#include <string>
#include <vector>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::recording {

class BagPlayer final : public runtime::Component {
 public:
  BagPlayer(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  struct Item {
    std::size_t publisher;
    std::uint64_t log_time;
    msg::RawSample sample;
  };
  void tick();

  std::string file_;
  double rate_;
  bool loop_;
  std::int64_t wait_ns_;
  bool playing_ = false;
  std::int64_t matched_at_ = 0;
  std::vector<std::unique_ptr<runtime::RawPublisher>> publishers_;
  std::vector<std::string> publisher_topics_;
  std::vector<Item> items_;  // in log-time order
  std::size_t next_ = 0;
  std::uint64_t published_ = 0, failed_ = 0, loops_ = 0;
  std::int64_t start_mono_ns_ = 0;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::recording
