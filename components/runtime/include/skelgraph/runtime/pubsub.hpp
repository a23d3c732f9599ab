#pragma once
// RAII DDS endpoints typed by the wire types. Readers deliver samples on the
// component's executor thread; writers and readers count what passes for the
// status report. Destroying one removes its DDS entity.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
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

struct SampleMeta {
  std::int64_t source_stamp_ns = 0;  // writer's clock when written
  std::int64_t receive_ns = 0;       // our wall clock when taken
};

// Untyped halves; use Publisher<T>, Subscription<T> or RawSubscription.
class WriterBase {
 public:
  WriterBase(Context& ctx, const std::string& topic, eprosima::fastdds::dds::TopicDataType* support,
             const QosPreset& qos);
  ~WriterBase();
  WriterBase(const WriterBase&) = delete;
  WriterBase& operator=(const WriterBase&) = delete;
  bool write(void* sample);
  std::size_t matched() const;
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const;
  // Reliable writers: waits until every matched reader acknowledged.
  bool wait_for_acks(std::chrono::milliseconds timeout);

 private:
  struct Listener;
  Context& ctx_;
  QosPreset qos_;
  std::unique_ptr<Listener> listener_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::shared_ptr<EndpointCounter> counter_;
};

class ReaderBase {
 public:
  using Deliver = std::function<void(void* sample, const SampleMeta&)>;
  ReaderBase(Context& ctx, const std::string& topic, eprosima::fastdds::dds::TopicDataType* support,
             const QosPreset& qos, Deliver deliver);
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
  Subscription(Context& ctx, const TopicDef<T>& topic, Callback cb) : Subscription(ctx, topic, topic.qos, std::move(cb)) {}
  // With another QoS than the topic's: e.g. newest_only() for a display.
  Subscription(Context& ctx, const TopicDef<T>& topic, const QosPreset& qos, Callback cb)
      : base_(ctx, topic.name, make_type_support<T>(), qos,
              [cb = std::move(cb)](void* s, const SampleMeta& m) { cb(*static_cast<const T*>(s), m); }) {}
  std::size_t matched() const { return base_.matched(); }
  bool wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const {
    return base_.wait_for_matched(n, timeout);
  }

 private:
  ReaderBase base_;
};

// Registers the raw support for `type_name` unless the participant has one;
// returns the support the participant uses for that name.
std::shared_ptr<eprosima::fastdds::dds::TopicDataType> registered_raw_type(Context& ctx, const std::string& topic,
                                                                           const std::string& type_name, bool keyed);

// Publishes serialized CDR on any topic, without knowing its type (bag play).
// Where this participant already knows the type typed, the payload is
// deserialized into a typed sample first.
class RawPublisher {
 public:
  RawPublisher(Context& ctx, const std::string& topic, const std::string& type_name, bool keyed, const QosPreset& qos);
  ~RawPublisher();
  RawPublisher(const RawPublisher&) = delete;
  RawPublisher& operator=(const RawPublisher&) = delete;
  // False when the payload does not decode as the participant's typed support, or DDS refuses it.
  bool publish(const msg::RawSample& sample);
  std::size_t matched() const { return base_.matched(); }

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
