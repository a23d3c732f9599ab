#pragma once
// A wire type to its serialized payload (CDR with the 4-byte encapsulation
// header, exactly what DDS sends): what recordings store as MCAP `cdr`.

#include <cstdint>
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

}  // namespace skelgraph::msg
