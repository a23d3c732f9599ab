#include "skelgraph/runtime/topics.hpp"

#include <algorithm>

#include "skelgraph/msg/message_table.hpp"

namespace skelgraph::runtime {

namespace {
template <class T>
TopicInfo info(const TopicDef<T>& def) {
  return TopicInfo{def.name, msg::MessageTraits<T>::name, def.qos};
}
}  // namespace

const std::vector<TopicInfo>& known_topics() {
  static const std::vector<TopicInfo> table = {
      info(topics::kSync),         info(topics::kSyncSession),   info(topics::kSyncControl),
      info(topics::kSyncAck),      info(topics::kSyncClock),      info(topics::kSkeletonRaw),   info(topics::kSensorFrame),   info(topics::kSkeletonFused),
      info(topics::kSkeletonTruth), info(topics::kDepth),        info(topics::kCalibration),
      info(topics::kGestureEvent), info(topics::kGestureState), info(topics::kCloud),
      info(topics::kPlayControl), info(topics::kPlayState),
      info(topics::kRobotState), info(topics::kRobotCommand), info(topics::kSafety),
      info(topics::kStatus)};
  return table;
}

const TopicInfo* find_topic(const std::string& name) {
  for (const auto& t : known_topics()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

ReaderPlan reader_plan(const TopicInfo& topic, int min_depth, int keep_all_depth) {
  const auto* m = msg::find_message(topic.type_name);
  ReaderPlan p{topic.type_name, m != nullptr && m->keyed, topic.qos};
  p.qos.depth = p.qos.depth == 0 ? keep_all_depth : std::max(p.qos.depth, min_depth);
  return p;
}

}  // namespace skelgraph::runtime
