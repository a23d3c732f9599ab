#pragma once
// A wire type to its serialized payload (CDR with the 4-byte encapsulation
// header, exactly what DDS sends): what recordings store as MCAP `cdr`.

#include <algorithm>
#include <cstdint>
#include <string>
#include <stdexcept>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "skelgraph/msg/messages.hpp"

namespace skelgraph::msg {

template <class T>
std::vector<std::uint8_t> to_cdr(const T& value) {
  typename MessageTraits<T>::PubSubType support;
  auto* v = const_cast<T*>(&value);
  eprosima::fastrtps::rtps::SerializedPayload_t payload(support.getSerializedSizeProvider(v)());
  if (!support.serialize(v, &payload)) throw std::runtime_error(std::string("cannot serialize a ") + MessageTraits<T>::name);
  return {payload.data, payload.data + payload.length};
}

// Throws std::runtime_error when the bytes are not a T.
template <class T>
T from_cdr(const void* data, std::size_t size) {
  typename MessageTraits<T>::PubSubType support;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  std::copy_n(static_cast<const std::uint8_t*>(data), size, payload.data);
  payload.length = static_cast<std::uint32_t>(size);
  T value;
  bool ok = false;
  try {
    ok = support.deserialize(&payload, &value);
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok) throw std::runtime_error("cannot decode " + std::to_string(size) + " bytes as " + MessageTraits<T>::name);
  return value;
}

// Skeletons of every schema (schema.hpp): older ones are read as the current type.
template <>
Skeleton from_cdr<Skeleton>(const void* data, std::size_t size);

}  // namespace skelgraph::msg
