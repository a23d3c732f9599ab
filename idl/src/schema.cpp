#include "skelgraph/msg/schema.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include "skelgraph/msg/cdr.hpp"

namespace skelgraph::msg {

namespace {
// The current decoder, without the fallback to older schemas.
bool decode_current(const void* data, std::size_t size, Skeleton& out) {
  SkeletonPubSubType support;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  std::copy_n(static_cast<const std::uint8_t*>(data), size, payload.data);
  payload.length = static_cast<std::uint32_t>(size);
  try {
    return support.deserialize(&payload, &out);
  } catch (const std::exception&) {
    return false;
  }
}
}  // namespace

std::optional<Skeleton> skeleton_from_schema1(const void* data, std::size_t size) {
  // Schema 1: the fields of schema 2 up to `joints`, nothing after them.
  std::vector<char> copy(static_cast<const char*>(data), static_cast<const char*>(data) + size);
  eprosima::fastcdr::FastBuffer buffer(copy.data(), copy.size());
  eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
  Skeleton s;
  try {
    cdr.read_encapsulation();
    std::string text;
    cdr >> text;
    if (text.size() > 64) return std::nullopt;
    s.sensor_id(text);
    std::uint32_t person = 0;
    cdr >> person;
    s.person_id(person);
    cdr >> text;
    if (text.size() > 64) return std::nullopt;
    s.frame_id(text);
    std::int64_t stamp = 0;
    std::uint64_t frame = 0;
    cdr >> stamp >> frame;
    s.stamp_ns(stamp);
    s.frame_number(frame);
    for (auto& j : s.joints()) j.deserialize(cdr);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  // Exactly one schema-1 skeleton: nothing but alignment padding left over.
  if (size - cdr.getSerializedDataLength() > 3) return std::nullopt;
  s.capture_oldest_ns(s.stamp_ns());
  s.capture_newest_ns(s.stamp_ns());
  return s;
}

template <>
Skeleton from_cdr<Skeleton>(const void* data, std::size_t size) {
  Skeleton value;
  if (decode_current(data, size, value)) return value;
  if (auto old = skeleton_from_schema1(data, size)) return *old;
  throw std::runtime_error("cannot decode " + std::to_string(size) + " bytes as " + MessageTraits<Skeleton>::name +
                           " (schema " + std::to_string(kSkeletonSchema) + " or 1)");
}

bool may_be_older_schema(const std::string& type_name, const std::string& schema_text) {
  return type_name == MessageTraits<Skeleton>::name && schema_text.find("capture_oldest_ns") == std::string::npos;
}

std::optional<std::vector<std::uint8_t>> upgrade_cdr(const std::string& type_name, const void* data, std::size_t size) {
  if (type_name != MessageTraits<Skeleton>::name) return std::nullopt;
  Skeleton current;
  if (decode_current(data, size, current)) return std::nullopt;
  if (auto old = skeleton_from_schema1(data, size)) return to_cdr(*old);
  return std::nullopt;
}

}  // namespace skelgraph::msg
