#pragma once
// A component's window on DDS: one DomainParticipant named after the component,
// created from an XML profile, plus the executor that runs the component's
// callbacks and the counters its status reports.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/executor.hpp"

namespace eprosima::fastdds::dds {
class DataWriter;
class DomainParticipant;
class DomainParticipantListener;
class Publisher;
class Subscriber;
class Topic;
class TopicDataType;
}  // namespace eprosima::fastdds::dds

namespace skelgraph::runtime {

// Counts of one input or output, shared between the endpoint and the status report.
struct EndpointCounter {
  std::string topic;
  bool is_output = false;
  // The endpoint's QoS as far as matching goes: a reader matches a writer that
  // offers at least what it asks (reliable, transient local).
  bool reliable = true;
  bool transient_local = false;
  std::atomic<std::uint64_t> count{0};
  std::atomic<std::uint64_t> dropped{0};    // outputs: writes DDS refused; inputs: samples rejected or lost
  std::atomic<std::uint64_t> instances{0};  // keyed outputs: instances written and not yet disposed

  // Something this component did failed here (a write DDS refused, a sample
  // our reader had no room for): the component is DEGRADED while it is recent.
  void note_failure(const std::string& what, std::int64_t mono_ns);
  struct Failures {
    std::uint64_t count = 0;
    std::int64_t last_mono_ns = 0;
    std::string last;  // what the last one was
  };
  Failures failures() const;

  // Remote endpoints currently matched (set from DDS listener threads).
  void set_matched(int n);
  std::size_t matched() const;
  bool wait_matched(std::size_t n, std::chrono::milliseconds timeout) const;

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  std::size_t matched_ = 0;
  Failures failures_;
};

enum class HealthState { Ok, Degraded, Error };

class AuthWatch;  // context.cpp: which secure participants have authenticated

class Context {
 public:
  // Throws std::runtime_error with the profile and domain if DDS refuses.
  // `listener` (optional, not owned) gets discovery callbacks from the start.
  Context(std::string name, const DdsConfig& config,
          eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& name() const { return name_; }
  const DdsConfig& config() const { return config_; }
  Executor& executor() { return executor_; }
  eprosima::fastdds::dds::DomainParticipant& participant() { return *participant_; }

  // The component's clock (the configuration's): now_ns() for message
  // stamps, monotonic_ns() for pacing and intervals.
  const Clock& clock() const { return *clock_; }
  const std::shared_ptr<const Clock>& clock_ptr() const { return clock_; }

  // Shared DDS entities, created on first use.
  eprosima::fastdds::dds::Publisher& publisher();
  eprosima::fastdds::dds::Subscriber& subscriber();
  // Registers the type if needed (takes ownership of `support`) and returns the
  // topic; throws if the name is already bound to another type.
  eprosima::fastdds::dds::Topic& topic(const std::string& name, eprosima::fastdds::dds::TopicDataType* support);

  std::shared_ptr<EndpointCounter> add_counter(const std::string& topic, bool is_output);

  // Reliable writers register here so flush() can wait until readers have
  // everything (used at shutdown, so a final STOP is not lost).
  void track_reliable_writer(eprosima::fastdds::dds::DataWriter* w);
  void untrack_reliable_writer(eprosima::fastdds::dds::DataWriter* w);
  bool flush(std::chrono::milliseconds timeout);
  std::vector<std::shared_ptr<EndpointCounter>> counters() const;

  // With a secure profile: the remote participants (with credentials) this
  // one has known for longer than `after` without either side finishing the
  // authentication handshake, as "name (guid prefix)". Fast DDS 2.9 leaves
  // such a pair for good (docs/security.md); empty without security.
  struct Unauthenticated {
    std::string who;        // "name (guid prefix)"
    std::int64_t since_ns;  // monotonic: when it was discovered
    bool again = false;     // the same component of the same host was stuck with us before, and restarted
  };
  std::vector<Unauthenticated> unauthenticated(std::chrono::milliseconds after);

  // The component's health, reported on skelgraph/status: what it set,
  // made DEGRADED by failures of its endpoints (EndpointCounter::note_failure)
  // within the last `failure_window` (the whole run: the launcher's final report).
  void set_health(HealthState state, std::string message);
  std::pair<HealthState, std::string> health(std::chrono::nanoseconds failure_window = kFailureWindow) const;
  static constexpr std::chrono::nanoseconds kFailureWindow = std::chrono::seconds(10);

 private:
  std::string name_;
  DdsConfig config_;
  std::shared_ptr<const Clock> clock_;
  std::unique_ptr<AuthWatch> auth_watch_;  // the participant's listener when secure: outlives it
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  // The profile's "skelgraph.type_information" property (type_policy.hpp).
  bool announce_type_information_ = true;
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<EndpointCounter>> counters_;
  std::vector<eprosima::fastdds::dds::DataWriter*> reliable_writers_;
  HealthState health_ = HealthState::Ok;
  std::string health_message_;
  Executor executor_;
};

}  // namespace skelgraph::runtime
