#pragma once
// Watches DDS discovery: which participants, writers and readers exist on the
// domain, on which topics with which types. Backs `skelgraph topic list` and
// lets echo/hz find a topic's type.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>

#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::runtime {

struct EndpointInfo {
  std::string guid;
  std::string participant;  // participant name (for us: the component)
  std::string topic;
  std::string type_name;
  bool is_writer = false;
  bool keyed = false;
  Reliability reliability = Reliability::BestEffort;
  Durability durability = Durability::Volatile;
};

struct TopicSummary {
  std::string name;
  std::vector<std::string> type_names;  // more than one is a misconfiguration worth seeing
  std::size_t writers = 0;
  std::size_t readers = 0;
  std::vector<std::string> participants;
};

class DiscoveryObserver final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant* p,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant* p,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;
  void on_subscriber_discovery(eprosima::fastdds::dds::DomainParticipant* p,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override;

  std::vector<EndpointInfo> endpoints() const;
  std::vector<TopicSummary> topics() const;  // sorted by name
  std::vector<std::string> participants() const;
  // Waits until a writer on `topic` is known; returns it.
  bool wait_for_writer(const std::string& topic, std::chrono::milliseconds timeout, EndpointInfo* out) const;

 private:
  void upsert(EndpointInfo e, bool removed);
  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  std::map<std::string, std::string> participant_names_;  // guid prefix -> name
  std::map<std::string, EndpointInfo> endpoints_;         // guid -> endpoint
};

}  // namespace skelgraph::runtime
