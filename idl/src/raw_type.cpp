#include "skelgraph/msg/raw_type.hpp"

#include <cstring>

namespace skelgraph::msg {

using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

RawPubSubType::RawPubSubType(const std::string& type_name, bool keyed, std::uint32_t max_size) {
  setName(type_name.c_str());
  m_typeSize = max_size;
  m_isGetKeyDefined = keyed;
  // Never announce a type object for a type we do not know the shape of.
  auto_fill_type_object(false);
  auto_fill_type_information(false);
}

bool RawPubSubType::serialize(void* data, SerializedPayload_t* payload) {
  const auto* s = static_cast<RawSample*>(data);
  if (s->payload.size() < 4 || s->payload.size() > payload->max_size) return false;
  std::memcpy(payload->data, s->payload.data(), s->payload.size());
  payload->length = static_cast<std::uint32_t>(s->payload.size());
  // The encapsulation header's second byte says big (0) or little (1) endian.
  payload->encapsulation = (s->payload[1] & 1) != 0 ? CDR_LE : CDR_BE;
  return true;
}

bool RawPubSubType::deserialize(SerializedPayload_t* payload, void* data) {
  auto* s = static_cast<RawSample*>(data);
  s->payload.assign(payload->data, payload->data + payload->length);
  return true;
}

std::function<std::uint32_t()> RawPubSubType::getSerializedSizeProvider(void* data) {
  return [data]() { return static_cast<std::uint32_t>(static_cast<RawSample*>(data)->payload.size()); };
}

void* RawPubSubType::createData() { return new RawSample(); }
void RawPubSubType::deleteData(void* data) { delete static_cast<RawSample*>(data); }

bool RawPubSubType::getKey(void*, InstanceHandle_t* handle, bool) {
  if (!m_isGetKeyDefined) return false;
  *handle = InstanceHandle_t();
  handle->value[15] = 1;  // one constant, non-nil instance
  return true;
}

}  // namespace skelgraph::msg
