#pragma once
// A pass-through DDS type: samples are the serialized CDR payload (with its
// 4-byte encapsulation header), whatever the type. Tools use it to count,
// record and decode topics without compiling their type in.

#include <cstdint>
#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

namespace skelgraph::msg {

struct RawSample {
  std::vector<std::uint8_t> payload;  // CDR, starting with the encapsulation header
};

class RawPubSubType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  // `keyed` must match the writers' topic kind or DDS will not match them.
  RawPubSubType(const std::string& type_name, bool keyed, std::uint32_t max_size = 64u * 1024u * 1024u);

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  // Keys arrive as key hashes in the inline QoS; without them every sample is
  // one instance, which is all a pass-through reader needs.
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5 = false) override;
};

}  // namespace skelgraph::msg
