#include "skelgraph/runtime/pubsub.hpp"

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <stdexcept>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

namespace skelgraph::runtime {

namespace dds = eprosima::fastdds::dds;

namespace {

template <class Qos>
void apply(const QosPreset& p, Qos& q) {
  q.reliability().kind =
      p.reliability == Reliability::Reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  q.durability().kind =
      p.durability == Durability::TransientLocal ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  if (p.depth <= 0) {
    q.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  } else {
    q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = p.depth;
  }
}

std::int64_t to_ns(const eprosima::fastrtps::rtps::Time_t& t) {
  return static_cast<std::int64_t>(t.seconds()) * 1000000000LL + static_cast<std::int64_t>(t.nanosec());
}

}  // namespace

// ---- writer ----

struct WriterBase::Listener final : dds::DataWriterListener {
  std::shared_ptr<EndpointCounter> counter;
  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& s) override {
    counter->set_matched(s.current_count);
  }
};

WriterBase::WriterBase(Context& ctx, const std::string& topic, dds::TopicDataType* support, const QosPreset& qos)
    : ctx_(ctx), qos_(qos), listener_(std::make_unique<Listener>()) {
  auto& t = ctx.topic(topic, support);
  counter_ = ctx.add_counter(topic, true);
  listener_->counter = counter_;
  dds::DataWriterQos wq = dds::DATAWRITER_QOS_DEFAULT;
  apply(qos, wq);
  // Reliable writers announce what they have every 200 ms (Fast DDS: 3 s), so a
  // sample lost on the wire is repaired within a fraction of a second: a lost
  // gesture event or sync tick must not wait seconds. Measured in tests/integration/lan.sh.
  wq.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 200000000);
  writer_ = ctx.publisher().create_datawriter(&t, wq, listener_.get(), dds::StatusMask::publication_matched());
  if (writer_ == nullptr) {
    throw std::runtime_error("component '" + ctx.name() + "': could not create a writer on " + topic +
                             (ctx.config().security_dir.empty()
                                  ? std::string()
                                  : " (security: the permissions do not let host '" + ctx.config().host +
                                        "' publish it; see permissions.xml in " + ctx.config().security_dir + ")"));
  }
  if (qos.reliability == Reliability::Reliable) ctx.track_reliable_writer(writer_);
}

WriterBase::~WriterBase() {
  if (writer_ == nullptr) return;
  // Let reliable samples (a final STOP, say) reach their readers before the writer goes.
  if (qos_.reliability == Reliability::Reliable) {
    wait_for_acks(std::chrono::milliseconds(1000));
    ctx_.untrack_reliable_writer(writer_);
  }
  writer_->set_listener(nullptr);
  ctx_.publisher().delete_datawriter(writer_);
}

bool WriterBase::write(void* sample) {
  const bool ok = writer_->write(sample);
  if (ok) {
    counter_->count.fetch_add(1, std::memory_order_relaxed);
  } else {
    counter_->dropped.fetch_add(1, std::memory_order_relaxed);
  }
  return ok;
}

std::size_t WriterBase::matched() const { return counter_->matched(); }

bool WriterBase::wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const {
  return counter_->wait_matched(n, timeout);
}

bool WriterBase::wait_for_acks(std::chrono::milliseconds timeout) {
  const auto ms = timeout.count();
  const eprosima::fastrtps::Duration_t d(static_cast<std::int32_t>(ms / 1000),
                                         static_cast<std::uint32_t>((ms % 1000) * 1000000));
  return writer_->wait_for_acknowledgments(d) == ReturnCode_t::RETCODE_OK;
}

// ---- reader ----

struct ReaderBase::State final : dds::DataReaderListener, std::enable_shared_from_this<ReaderBase::State> {
  std::recursive_mutex mutex;  // held while delivering; the destructor takes it to stop deliveries
  bool alive = true;
  Executor* executor = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::DataReader* reader = nullptr;
  dds::TypeSupport type;
  void* sample = nullptr;
  Deliver deliver;
  std::shared_ptr<EndpointCounter> counter;
  std::atomic<bool> pending{false};

  ~State() override {
    if (sample != nullptr) type.delete_data(sample);
  }

  void on_data_available(dds::DataReader*) override {
    if (pending.exchange(true)) return;  // a drain is already queued
    std::weak_ptr<State> weak = shared_from_this();
    executor->post([weak] {
      if (auto s = weak.lock()) s->drain();
    });
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& s) override {
    counter->set_matched(s.current_count);
  }
  void on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& s) override {
    counter->dropped.fetch_add(static_cast<std::uint64_t>(s.total_count_change), std::memory_order_relaxed);
  }
  void on_sample_rejected(dds::DataReader*, const dds::SampleRejectedStatus& s) override {
    counter->dropped.fetch_add(static_cast<std::uint64_t>(s.total_count_change), std::memory_order_relaxed);
  }

  void drain() {
    std::lock_guard<std::recursive_mutex> lock(mutex);
    pending.store(false);
    if (!alive || reader == nullptr) return;
    dds::SampleInfo info;
    while (reader->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      counter->count.fetch_add(1, std::memory_order_relaxed);
      deliver(sample, SampleMeta{to_ns(info.source_timestamp), Context::now_ns()});
      if (!alive) return;
    }
  }
};

ReaderBase::ReaderBase(Context& ctx, const std::string& topic, dds::TopicDataType* support, const QosPreset& qos,
                       Deliver deliver)
    : state_(std::make_shared<State>()) {
  auto& t = ctx.topic(topic, support);
  state_->type = ctx.participant().find_type(t.get_type_name());
  state_->sample = state_->type.create_data();
  state_->executor = &ctx.executor();
  state_->subscriber = &ctx.subscriber();
  state_->deliver = std::move(deliver);
  state_->counter = ctx.add_counter(topic, false);
  dds::DataReaderQos rq = dds::DATAREADER_QOS_DEFAULT;
  apply(qos, rq);
  dds::StatusMask mask = dds::StatusMask::data_available();
  mask << dds::StatusMask::subscription_matched() << dds::StatusMask::sample_lost()
       << dds::StatusMask::sample_rejected();
  state_->reader = state_->subscriber->create_datareader(&t, rq, state_.get(), mask);
  if (state_->reader == nullptr) {
    throw std::runtime_error("component '" + ctx.name() + "': could not create a reader on " + topic +
                             (ctx.config().security_dir.empty()
                                  ? std::string()
                                  : " (security: the permissions do not let host '" + ctx.config().host +
                                        "' subscribe to it; see permissions.xml in " + ctx.config().security_dir + ")"));
  }
}

ReaderBase::~ReaderBase() {
  std::lock_guard<std::recursive_mutex> lock(state_->mutex);
  state_->alive = false;
  state_->reader->set_listener(nullptr);
  state_->subscriber->delete_datareader(state_->reader);
  state_->reader = nullptr;
}

std::size_t ReaderBase::matched() const { return state_->counter->matched(); }

bool ReaderBase::wait_for_matched(std::size_t n, std::chrono::milliseconds timeout) const {
  return state_->counter->wait_matched(n, timeout);
}

std::shared_ptr<dds::TopicDataType> registered_raw_type(Context& ctx, const std::string& topic,
                                                        const std::string& type_name, bool keyed) {
  ctx.topic(topic, new msg::RawPubSubType(type_name, keyed));  // registers the raw support unless one exists
  return ctx.participant().find_type(type_name);
}

RawPublisher::RawPublisher(Context& ctx, const std::string& topic, const std::string& type_name, bool keyed,
                           const QosPreset& qos)
    : type_(registered_raw_type(ctx, topic, type_name, keyed)),
      base_(ctx, topic, new msg::RawPubSubType(type_name, keyed), qos) {
  if (dynamic_cast<msg::RawPubSubType*>(type_.get()) == nullptr) typed_ = type_->createData();
}

RawPublisher::~RawPublisher() {
  if (typed_ != nullptr) type_->deleteData(typed_);
}

bool RawPublisher::publish(const msg::RawSample& sample) {
  if (typed_ == nullptr) return base_.write(const_cast<msg::RawSample*>(&sample));
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(sample.payload.size()));
  std::copy(sample.payload.begin(), sample.payload.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(sample.payload.size());
  bool ok = false;
  try {
    ok = type_->deserialize(&payload, typed_);
  } catch (const std::exception&) {
    ok = false;
  }
  return ok && base_.write(typed_);
}

void RawSubscription::deliver(void* sample, const SampleMeta& m) {
  if (dynamic_cast<msg::RawPubSubType*>(type_.get()) != nullptr) {
    cb_(*static_cast<const msg::RawSample*>(sample), m);
    return;
  }
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type_->getSerializedSizeProvider(sample)());
  if (!type_->serialize(sample, &payload)) return;
  scratch_.payload.assign(payload.data, payload.data + payload.length);
  cb_(scratch_, m);
}

}  // namespace skelgraph::runtime
