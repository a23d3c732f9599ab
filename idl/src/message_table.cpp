#include "skelgraph/msg/message_table.hpp"

#include <memory>
#include <stdexcept>

#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/json.hpp"
#include "skelgraph/msg/messages.hpp"

namespace skelgraph::msg {

namespace {

template <class T>
MessageInfo make_info() {
  using Support = typename MessageTraits<T>::PubSubType;
  MessageInfo info;
  info.type_name = MessageTraits<T>::name;
  info.keyed = T::isKeyDefined();
  info.make_type_support = [] { return new Support(); };
  info.decode = [](const std::vector<std::uint8_t>& bytes) {
    return nlohmann::json(from_cdr<T>(bytes.data(), bytes.size()));
  };
  return info;
}

}  // namespace

const std::vector<MessageInfo>& message_table() {
  static const std::vector<MessageInfo> table = {
      make_info<Skeleton>(),   make_info<SyncCommand>(),  make_info<SyncControl>(),
      make_info<SyncAck>(),    make_info<SensorPose>(),   make_info<DepthFrame>(),
      make_info<GestureEvent>(), make_info<ComponentStatus>(), make_info<ClockOffset>(),
      make_info<TickFrames>(), make_info<SensorFrame>(), make_info<GestureState>(),
      make_info<PointCloud>(), make_info<PlayControl>(), make_info<PlayState>(),
      make_info<RobotState>(), make_info<RobotCommand>(), make_info<SafetyStatus>()};
  return table;
}

const MessageInfo* find_message(const std::string& type_name) {
  for (const auto& m : message_table()) {
    if (m.type_name == type_name) return &m;
  }
  return nullptr;
}

}  // namespace skelgraph::msg
