#include "skelgraph/runtime/pubsub.hpp"

#include "skelgraph/msg/message_table.hpp"

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
void apply(const QosPreset& p, bool keyed, Qos& q) {
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
  // Resource limits always set here (QosPreset), never Fast DDS's defaults.
  const int instances = keyed ? std::max(1, p.max_instances) : 1;
  const int per_instance = p.depth > 0 ? p.depth : QosPreset::kKeepAllSamples;
  auto& rl = q.resource_limits();
  rl.max_instances = instances;
  rl.max_samples_per_instance = per_instance;
  rl.max_samples = instances * per_instance;
  rl.allocated_samples = std::min(rl.max_samples, 100);
}

InstanceId to_id(const eprosima::fastrtps::rtps::InstanceHandle_t& h) {
  InstanceId id{};
  for (std::size_t i = 0; i < id.size(); ++i) id[i] = h.value[static_cast<unsigned>(i)];
  return id;
}

eprosima::fastrtps::rtps::InstanceHandle_t to_handle(const InstanceId& id) {
  eprosima::fastrtps::rtps::InstanceHandle_t h;
  for (std::size_t i = 0; i < id.size(); ++i) h.value[static_cast<unsigned>(i)] = id[i];  // (marks it defined)
  return h;
}

const char* return_code_name(int code) {
  switch (code) {
    case ReturnCode_t::RETCODE_OK: return "OK";
    case ReturnCode_t::RETCODE_ERROR: return "ERROR";
    case ReturnCode_t::RETCODE_BAD_PARAMETER: return "BAD_PARAMETER";
    case ReturnCode_t::RETCODE_PRECONDITION_NOT_MET: return "PRECONDITION_NOT_MET";
    case ReturnCode_t::RETCODE_OUT_OF_RESOURCES: return "OUT_OF_RESOURCES";
    case ReturnCode_t::RETCODE_NOT_ENABLED: return "NOT_ENABLED";
    case ReturnCode_t::RETCODE_TIMEOUT: return "TIMEOUT";
    default: return "refused";
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
  type_ = ctx.participant().find_type(t.get_type_name());
  keyed_ = type_->m_isGetKeyDefined;
  counter_ = ctx.add_counter(topic, true);
  counter_->reliable = qos.reliability == Reliability::Reliable;
  counter_->transient_local = qos.durability == Durability::TransientLocal;
  listener_->counter = counter_;
  dds::DataWriterQos wq = dds::DATAWRITER_QOS_DEFAULT;
  apply(qos, keyed_, wq);
  // Unregistering an instance disposes it too: readers learn the person left.
  wq.writer_data_lifecycle().autodispose_unregistered_instances = true;
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

void WriterBase::failed(const char* what, int return_code) {
  counter_->dropped.fetch_add(1, std::memory_order_relaxed);
  counter_->note_failure(std::string(what) + " " + return_code_name(return_code) +
                             (keyed_ ? " with " + std::to_string(counter_->instances.load()) + " instance(s) alive" : std::string()),
                         ctx_.clock().monotonic_ns());
}

bool WriterBase::write(void* sample, std::int64_t active_ns) {
  std::map<InstanceId, Instance>::iterator it;
  if (keyed_) {
    eprosima::fastrtps::rtps::InstanceHandle_t h;
    type_->getKey(sample, &h, false);
    std::lock_guard<std::mutex> lock(mutex_);
    it = instances_.find(to_id(h));
    if (it == instances_.end()) {
      // New here: registered, so that dispose_idle() can ask the writer for its key later.
      const auto dds_handle = writer_->register_instance(sample);
      if (!dds_handle.isDefined()) {
        failed("write: a new instance", ReturnCode_t::RETCODE_OUT_OF_RESOURCES);
        return false;
      }
      it = instances_.emplace(to_id(h), Instance{to_id(dds_handle), 0}).first;
      counter_->instances.store(instances_.size(), std::memory_order_relaxed);
    }
    it->second.last_active_ns = active_ns == kNow ? ctx_.clock().monotonic_ns() : active_ns;
  }
  const auto rc = writer_->write(sample, eprosima::fastrtps::rtps::c_InstanceHandle_Unknown);
  if (rc != ReturnCode_t::RETCODE_OK) {
    failed("write", rc());
    return false;
  }
  counter_->count.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool WriterBase::unregister(void* key_holder, const Instance& instance) {
  const auto rc = writer_->unregister_instance(key_holder, to_handle(instance.dds_handle));
  if (rc != ReturnCode_t::RETCODE_OK) {
    failed("dispose", rc());
    return false;
  }
  return true;
}

bool WriterBase::dispose(void* sample) {
  if (!keyed_) return false;
  eprosima::fastrtps::rtps::InstanceHandle_t h;
  type_->getKey(sample, &h, false);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = instances_.find(to_id(h));
  if (it == instances_.end()) return false;
  const bool ok = unregister(sample, it->second);
  instances_.erase(it);  // refused or not, this writer is done with it
  counter_->instances.store(instances_.size(), std::memory_order_relaxed);
  return ok;
}

std::size_t WriterBase::dispose_idle(std::int64_t before_ns) {
  if (!keyed_) return 0;
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t n = 0;
  void* key = nullptr;
  for (auto it = instances_.begin(); it != instances_.end();) {
    if (it->second.last_active_ns >= before_ns) {
      ++it;
      continue;
    }
    if (key == nullptr) key = type_->createData();
    if (writer_->get_key_value(key, to_handle(it->second.dds_handle)) == ReturnCode_t::RETCODE_OK &&
        unregister(key, it->second)) {
      ++n;
    }
    it = instances_.erase(it);
  }
  if (key != nullptr) type_->deleteData(key);
  counter_->instances.store(instances_.size(), std::memory_order_relaxed);
  return n;
}

std::size_t WriterBase::live_instances() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return instances_.size();
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
  Gone gone;
  std::shared_ptr<const Clock> clock;
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
    // Our reader had no room (resource limits): ours to fix, unlike a sample lost on the wire.
    const char* why = s.last_reason == dds::REJECTED_BY_INSTANCES_LIMIT           ? "instance limit"
                      : s.last_reason == dds::REJECTED_BY_SAMPLES_PER_INSTANCE_LIMIT ? "samples-per-instance limit"
                      : s.last_reason == dds::REJECTED_BY_SAMPLES_LIMIT            ? "sample limit"
                                                                                 : "rejected";
    counter->note_failure(why, clock->monotonic_ns());
  }

  void drain() {
    std::lock_guard<std::recursive_mutex> lock(mutex);
    pending.store(false);
    if (!alive || reader == nullptr) return;
    dds::SampleInfo info;
    while (reader->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
      const SampleMeta meta{to_ns(info.source_timestamp), clock->now_ns(), to_id(info.instance_handle)};
      if (!info.valid_data) {
        // The writer disposed or unregistered the instance: it is gone.
        if (gone && info.instance_state != dds::ALIVE_INSTANCE_STATE) gone(meta);
      } else {
        counter->count.fetch_add(1, std::memory_order_relaxed);
        deliver(sample, meta);
      }
      if (!alive) return;
    }
  }
};

ReaderBase::ReaderBase(Context& ctx, const std::string& topic, dds::TopicDataType* support, const QosPreset& qos,
                       Deliver deliver, Gone gone)
    : state_(std::make_shared<State>()) {
  auto& t = ctx.topic(topic, support);
  state_->type = ctx.participant().find_type(t.get_type_name());
  state_->sample = state_->type.create_data();
  state_->executor = &ctx.executor();
  state_->subscriber = &ctx.subscriber();
  state_->deliver = std::move(deliver);
  state_->gone = std::move(gone);
  state_->clock = ctx.clock_ptr();
  state_->counter = ctx.add_counter(topic, false);
  state_->counter->reliable = qos.reliability == Reliability::Reliable;
  state_->counter->transient_local = qos.durability == Durability::TransientLocal;
  dds::DataReaderQos rq = dds::DATAREADER_QOS_DEFAULT;
  apply(qos, state_->type->m_isGetKeyDefined, rq);
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

namespace {
// One of our own types is published typed, so that keyed samples are written
// as their own instances (the raw type cannot see keys) and can be disposed.
std::shared_ptr<dds::TopicDataType> publisher_type(Context& ctx, const std::string& topic, const std::string& type_name,
                                                   bool keyed) {
  const auto* known = msg::find_message(type_name);
  if (known != nullptr && known->keyed == keyed && ctx.participant().find_type(type_name).empty()) {
    auto* support = known->make_type_support();
    apply_type_policy(*support);
    ctx.topic(topic, support);
    return ctx.participant().find_type(type_name);
  }
  return registered_raw_type(ctx, topic, type_name, keyed);
}
}  // namespace

RawPublisher::RawPublisher(Context& ctx, const std::string& topic, const std::string& type_name, bool keyed,
                           const QosPreset& qos)
    : type_(publisher_type(ctx, topic, type_name, keyed)),
      base_(ctx, topic, new msg::RawPubSubType(type_name, keyed), qos) {
  if (dynamic_cast<msg::RawPubSubType*>(type_.get()) == nullptr) typed_ = type_->createData();
}

RawPublisher::~RawPublisher() {
  if (typed_ != nullptr) type_->deleteData(typed_);
}

bool RawPublisher::publish(const msg::RawSample& sample, std::int64_t active_ns) {
  if (typed_ == nullptr) return base_.write(const_cast<msg::RawSample*>(&sample), active_ns);
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(sample.payload.size()));
  std::copy(sample.payload.begin(), sample.payload.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(sample.payload.size());
  bool ok = false;
  try {
    ok = type_->deserialize(&payload, typed_);
  } catch (const std::exception&) {
    ok = false;
  }
  return ok && base_.write(typed_, active_ns);
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
