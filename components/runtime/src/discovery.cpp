#include "skelgraph/runtime/discovery.hpp"

#include <algorithm>
#include <set>
#include <sstream>

#include <fastdds/rtps/common/Guid.h>

namespace skelgraph::runtime {

namespace rtps = eprosima::fastrtps::rtps;

namespace {
template <class T>
std::string str(const T& v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
}  // namespace

void DiscoveryObserver::on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                                 rtps::ParticipantDiscoveryInfo&& info) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto prefix = str(info.info.m_guid.guidPrefix);
  if (info.status == rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT ||
      info.status == rtps::ParticipantDiscoveryInfo::CHANGED_QOS_PARTICIPANT) {
    participant_names_[prefix] = info.info.m_participantName.to_string();
    for (auto& [guid, e] : endpoints_) {
      if (guid.rfind(prefix, 0) == 0) e.participant = participant_names_[prefix];
    }
  } else {
    participant_names_.erase(prefix);
    for (auto it = endpoints_.begin(); it != endpoints_.end();) {
      it = it->first.rfind(prefix, 0) == 0 ? endpoints_.erase(it) : std::next(it);
    }
  }
  cv_.notify_all();
}

namespace {
// Writer and reader proxy data have the same accessors.
template <class ProxyData>
EndpointInfo endpoint_from(const ProxyData& d, bool is_writer) {
  EndpointInfo e;
  e.guid = str(d.guid());
  e.topic = d.topicName().to_string();
  e.type_name = d.typeName().to_string();
  e.is_writer = is_writer;
  e.keyed = d.topicKind() == rtps::WITH_KEY;
  e.reliability = d.m_qos.m_reliability.kind == eprosima::fastdds::dds::RELIABLE_RELIABILITY_QOS
                      ? Reliability::Reliable
                      : Reliability::BestEffort;
  e.durability = d.m_qos.m_durability.kind == eprosima::fastdds::dds::VOLATILE_DURABILITY_QOS
                     ? Durability::Volatile
                     : Durability::TransientLocal;
  return e;
}
}  // namespace

void DiscoveryObserver::on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                               rtps::WriterDiscoveryInfo&& info) {
  upsert(endpoint_from(info.info, true), info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER);
}

void DiscoveryObserver::on_subscriber_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                                rtps::ReaderDiscoveryInfo&& info) {
  upsert(endpoint_from(info.info, false), info.status == rtps::ReaderDiscoveryInfo::REMOVED_READER);
}

void DiscoveryObserver::upsert(EndpointInfo e, bool removed) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (removed) {
      endpoints_.erase(e.guid);
    } else {
      for (const auto& [prefix, name] : participant_names_) {
        if (e.guid.rfind(prefix, 0) == 0) e.participant = name;
      }
      endpoints_[e.guid] = std::move(e);
    }
  }
  cv_.notify_all();
}

std::vector<EndpointInfo> DiscoveryObserver::endpoints() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<EndpointInfo> out;
  for (const auto& [guid, e] : endpoints_) out.push_back(e);
  return out;
}

std::vector<TopicSummary> DiscoveryObserver::topics() const {
  std::map<std::string, TopicSummary> by_name;
  std::map<std::string, std::set<std::string>> types, parts;
  for (const auto& e : endpoints()) {
    auto& t = by_name[e.topic];
    t.name = e.topic;
    (e.is_writer ? t.writers : t.readers)++;
    types[e.topic].insert(e.type_name);
    if (!e.participant.empty()) parts[e.topic].insert(e.participant);
  }
  std::vector<TopicSummary> out;
  for (auto& [name, t] : by_name) {
    t.type_names.assign(types[name].begin(), types[name].end());
    t.participants.assign(parts[name].begin(), parts[name].end());
    out.push_back(std::move(t));
  }
  return out;
}

std::vector<std::string> DiscoveryObserver::participants() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> out;
  for (const auto& [prefix, name] : participant_names_) out.push_back(name);
  std::sort(out.begin(), out.end());
  return out;
}

bool DiscoveryObserver::wait_for_writer(const std::string& topic, std::chrono::milliseconds timeout,
                                        EndpointInfo* out) const {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool found = cv_.wait_for(lock, timeout, [&] {
    for (const auto& [guid, e] : endpoints_) {
      if (e.is_writer && e.topic == topic) return true;
    }
    return false;
  });
  if (found && out != nullptr) {
    for (const auto& [guid, e] : endpoints_) {
      if (e.is_writer && e.topic == topic) {
        *out = e;
        break;
      }
    }
  }
  return found;
}

}  // namespace skelgraph::runtime
