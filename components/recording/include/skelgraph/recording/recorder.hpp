#pragma once
// `recorder` component: obeys the sync topic. START opens
// <directory>/<label>_<session>_<host>.mcap, every configured topic is
// recorded as it arrives (CDR as sent, our clock as log time, the writer's
// as publish time), every TICK is recorded and answered on skelgraph/sync_ack
// with this host's clocks, STOP closes the file. The latest samples of each
// transient-local topic (sensor poses, the session; as many as the topic keeps
// for late joiners) go into every new file.
// One recorder per host; several hosts record the same session.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "skelgraph/recording/session_recorder.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::recording {

class Recorder final : public runtime::Component {
 public:
  Recorder(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();

  void on_start() override;
  void on_shutdown() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  struct Latched {
    std::string topic, type_name;
    bool keyed;
    std::vector<std::uint8_t> cdr;
    std::int64_t log_ns, publish_ns;
  };
  void on_sample(const runtime::TopicInfo& topic, bool keyed, const msg::RawSample& s, const runtime::SampleMeta& m);
  void open(const std::string& label, std::uint32_t session_id);
  void close();
  void stop_session(std::chrono::milliseconds wait);  // close after `wait` (a sooner call shortens it)
  static constexpr std::chrono::milliseconds kSessionStopGrace{3000};
  void fail(const std::string& what);

  RecorderOptions options_;
  bool record_now_;
  std::string now_label_;
  std::vector<std::unique_ptr<runtime::RawSubscription>> subs_;
  runtime::Publisher<msg::SyncAck> ack_pub_;
  runtime::TimerHandle flush_timer_;
  std::chrono::milliseconds linger_{0};
  runtime::TimerHandle linger_timer_;
  bool linger_timer_active_ = false;
  std::chrono::milliseconds linger_wait_{0};
  std::unique_ptr<SessionRecorder> session_;
  std::vector<Latched> latched_;
  std::vector<std::string> topics_;
  std::vector<nlohmann::json> finished_;  // files closed so far
  std::uint64_t ticks_acked_ = 0;
  std::uint32_t session_id_ = 0;  // the session last opened (0: none yet)
  std::string last_error_;
};

}  // namespace skelgraph::recording
