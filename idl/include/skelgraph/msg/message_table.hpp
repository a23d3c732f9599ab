#pragma once
// What this build knows about each wire type, looked up by DDS type name:
// whether it is keyed, how to make its type support, how to decode a CDR
// payload to JSON. The one place tools go from "a type name seen on the wire"
// to behaviour.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace eprosima::fastdds::dds {
class TopicDataType;
}

namespace skelgraph::msg {

struct MessageInfo {
  std::string type_name;  // e.g. "skelgraph::msg::Skeleton"
  bool keyed = false;
  std::function<eprosima::fastdds::dds::TopicDataType*()> make_type_support;
  // Decodes a serialized payload (with encapsulation header); throws std::runtime_error.
  std::function<nlohmann::json(const std::vector<std::uint8_t>&)> decode;
};

// Every top-level type in idl/skelgraph.idl.
const std::vector<MessageInfo>& message_table();
// nullptr when the type is not one of ours.
const MessageInfo* find_message(const std::string& type_name);

}  // namespace skelgraph::msg
