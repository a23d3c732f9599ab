#pragma once
// RAII DDS endpoints typed by the wire types. Readers deliver samples on the
// component's executor thread; writers and readers count what passes for the
// status report. Destroying one removes its DDS entity.

#include <array>
#include <climits>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "skelgraph/msg/messages.hpp"
#include "skelgraph/msg/raw_type.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/runtime/type_policy.hpp"

namespace eprosima::fastdds::dds {
class DataWriter;
}

namespace skelgraph::runtime {

// A DDS instance (the key hash of a keyed sample; all zero for unkeyed topics).
using InstanceId = std::array<std::uint8_t, 16>;

struct SampleMeta {
  std::int64_t source_stamp_ns = 0;  // writer's clock when written
  std::int64_t receive_ns = 0;       // our wall clock when taken
  InstanceId instance{};
};

// Untyped halves; use Publisher<T>, Subscription<T> or RawSubscription.
class WriterBase {
 public:
  WriterBase(Context& ctx, const std::string& topic, eprosima::fastdds::dds::TopicDataType* support,
             const QosPreset& qos);
  ~WriterBase();
  WriterBase(const WriterBase&) = delete;
  WriterBase& operator=(const WriterBase&) = delete;
  // False when DDS refuses it: counted, and the component is DEGRADED for a
  // while. Keyed: `active_ns` is when the instance was last active, on a
  // clock of the caller's (default: the context's monotonic clock), for dispose_idle().
  static constexpr std::int64_t kNow = INT64_MIN;
  bool write(void* sample, std::int64_t active_ns = kNow);
  // Keyed topics: the writer disposes and unregisters the sample's instance
  // (readers see it NOT_ALIVE_DISPOSED; the writer's resources are freed once
  // readers have it). False when the instance is not alive or DDS refuses.
  bool dispose(void* sample);
  // Disposes every instance not active since `before_ns` (on the clock
  // write() was given); returns how many. For sources that cannot tell when a
  // person left (a data set or a recording replayed).
  std::size_t dispose_idle(std::int64_t before_ns);
  // Keyed topics: instances written and not disposed.
  std::size_t live_instances() const;
  std::size_t matched() const;
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const;
  // Reliable writers: waits until every matched reader acknowledged.
  bool wait_for_acks(std::chrono::milliseconds timeout);

 private:
  struct Listener;
  struct Instance {
    std::array<std::uint8_t, 16> dds_handle{};  // as the writer knows it (get_key_value)
    std::int64_t last_active_ns = 0;
  };
  bool unregister(void* key_holder, const Instance& instance);
  void failed(const char* what, int return_code);

  Context& ctx_;
  QosPreset qos_;
  std::shared_ptr<eprosima::fastdds::dds::TopicDataType> type_;  // the participant's support for the topic's type
  bool keyed_ = false;
  std::unique_ptr<Listener> listener_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::shared_ptr<EndpointCounter> counter_;
  mutable std::mutex mutex_;  // instances_ (a writer may be used from another thread than the executor)
  std::map<InstanceId, Instance> instances_;
};

class ReaderBase {
 public:
  using Deliver = std::function<void(void* sample, const SampleMeta&)>;
  // An instance the writer disposed or unregistered (meta.instance says which).
  using Gone = std::function<void(const SampleMeta&)>;
  ReaderBase(Context& ctx, const std::string& topic, eprosima::fastdds::dds::TopicDataType* support,
             const QosPreset& qos, Deliver deliver, Gone gone = nullptr);
  ~ReaderBase();
  ReaderBase(const ReaderBase&) = delete;
  ReaderBase& operator=(const ReaderBase&) = delete;
  std::size_t matched() const;
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const;

  struct State;

 private:
  std::shared_ptr<State> state_;
};

// Type support for a generated type, announcing what type_policy decides.
// (RawPubSubType announces nothing, so tools match any revision by name.)
template <class T>
eprosima::fastdds::dds::TopicDataType* make_type_support() {
  auto* support = new typename msg::MessageTraits<T>::PubSubType();
  apply_type_policy(*support);
  return support;
}

template <class T>
class Publisher {
 public:
  Publisher(Context& ctx, const TopicDef<T>& topic)
      : base_(ctx, topic.name, make_type_support<T>(), topic.qos) {}
  bool publish(const T& sample) { return base_.write(const_cast<T*>(&sample)); }
  // Keyed types: the instance of `key` (its key fields) is gone (see WriterBase::dispose).
  bool dispose(const T& key) { return base_.dispose(const_cast<T*>(&key)); }
  std::size_t dispose_idle(std::int64_t before_ns) { return base_.dispose_idle(before_ns); }
  std::size_t live_instances() const { return base_.live_instances(); }
  std::size_t matched() const { return base_.matched(); }
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const {
    return base_.wait_for_matched(n, timeout);
  }
  bool wait_for_acks(std::chrono::milliseconds timeout) { return base_.wait_for_acks(timeout); }

 private:
  WriterBase base_;
};

template <class T>
class Subscription {
 public:
  using Callback = std::function<void(const T&, const SampleMeta&)>;
  // A keyed instance its writer disposed: the last sample of it (its key
  // tells which person or sensor left), delivered once, on the executor.
  using GoneCallback = std::function<void(const T& last, const SampleMeta&)>;
  Subscription(Context& ctx, const TopicDef<T>& topic, Callback cb, GoneCallback gone = nullptr)
      : Subscription(ctx, topic, topic.qos, std::move(cb), std::move(gone)) {}
  // With another QoS than the topic's: e.g. newest_only() for a display.
  Subscription(Context& ctx, const TopicDef<T>& topic, const QosPreset& qos, Callback cb, GoneCallback gone = nullptr)
      : cb_(std::move(cb)),
        gone_(std::move(gone)),
        base_(ctx, topic.name, make_type_support<T>(), qos, [this](void* s, const SampleMeta& m) { deliver(s, m); },
              gone_ ? ReaderBase::Gone([this](const SampleMeta& m) { on_gone(m); }) : ReaderBase::Gone()) {}
  std::size_t matched() const { return base_.matched(); }
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const {
    return base_.wait_for_matched(n, timeout);
  }
  // Instances whose last sample is kept to be handed to the gone callback.
  std::size_t instances_held() const { return last_.size(); }

 private:
  // A writer that vanished without disposing (its host lost) leaves instances
  // no notice will end; their last samples are let go after this long.
  static constexpr std::int64_t kForgetNs = 60'000'000'000;

  void deliver(void* s, const SampleMeta& m) {
    const auto& sample = *static_cast<const T*>(s);
    if (gone_) {
      last_[m.instance] = {sample, m.receive_ns};
      if (m.receive_ns - last_sweep_ns_ > kForgetNs) {
        last_sweep_ns_ = m.receive_ns;
        for (auto it = last_.begin(); it != last_.end();) {
          it = m.receive_ns - it->second.second > kForgetNs ? last_.erase(it) : std::next(it);
        }
      }
    }
    cb_(sample, m);
  }
  void on_gone(const SampleMeta& m) {
    const auto it = last_.find(m.instance);
    if (it == last_.end()) return;  // never seen alive here (disposed before we matched)
    const T last = std::move(it->second.first);
    last_.erase(it);
    gone_(last, m);
  }

  Callback cb_;
  GoneCallback gone_;
  std::map<InstanceId, std::pair<T, std::int64_t>> last_;  // executor thread only
  std::int64_t last_sweep_ns_ = 0;
  ReaderBase base_;
};

// Registers the raw support for `type_name` unless the participant has one;
// returns the support the participant uses for that name.
std::shared_ptr<eprosima::fastdds::dds::TopicDataType> registered_raw_type(Context& ctx, const std::string& topic,
                                                                           const std::string& type_name, bool keyed);

// Publishes serialized CDR on any topic (bag play). Our own types (and any
// type this participant already knows typed) are deserialized into a typed
// sample first, so keyed samples keep their instances; others go out as
// they are.
class RawPublisher {
 public:
  RawPublisher(Context& ctx, const std::string& topic, const std::string& type_name, bool keyed, const QosPreset& qos);
  ~RawPublisher();
  RawPublisher(const RawPublisher&) = delete;
  RawPublisher& operator=(const RawPublisher&) = delete;
  // False when the payload does not decode as the participant's typed support, or DDS refuses it.
  bool publish(const msg::RawSample& sample, std::int64_t active_ns = WriterBase::kNow);
  std::size_t matched() const { return base_.matched(); }
  // Reliable writers: waits until every matched reader acknowledged.
  bool wait_for_acks(std::chrono::milliseconds timeout) { return base_.wait_for_acks(timeout); }
  // Keyed: disposes the instances not active since then (WriterBase::dispose_idle).
  std::size_t dispose_idle(std::int64_t before_ns) { return base_.dispose_idle(before_ns); }

 private:
  std::shared_ptr<eprosima::fastdds::dds::TopicDataType> type_;
  void* typed_ = nullptr;  // scratch sample when type_ is not raw
  WriterBase base_;
};

// Receives any topic as serialized CDR, without knowing its type. A
// participant has one type support per type name: when this one already
// reads or writes the type typed (a component recording its own status), the
// typed sample is serialized back, so the callback always gets the payload.
class RawSubscription {
 public:
  using Callback = std::function<void(const msg::RawSample&, const SampleMeta&)>;
  RawSubscription(Context& ctx, const std::string& topic, const std::string& type_name, bool keyed,
                  const QosPreset& qos, Callback cb)
      : cb_(std::move(cb)),
        type_(registered_raw_type(ctx, topic, type_name, keyed)),
        base_(ctx, topic, new msg::RawPubSubType(type_name, keyed), qos,
              [this](void* s, const SampleMeta& m) { deliver(s, m); }) {}
  std::size_t matched() const { return base_.matched(); }
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const {
    return base_.wait_for_matched(n, timeout);
  }

 private:
  void deliver(void* sample, const SampleMeta& m);

  Callback cb_;
  std::shared_ptr<eprosima::fastdds::dds::TopicDataType> type_;
  msg::RawSample scratch_;
  ReaderBase base_;
};

}  // namespace skelgraph::runtime
