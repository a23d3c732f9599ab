#include "skelgraph/runtime/type_policy.hpp"

#include <mutex>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <skelgraphTypeObject.h>

namespace skelgraph::runtime {

void register_type_objects() {
  static std::once_flag once;
  std::call_once(once, [] { registerskelgraphTypes(); });
}

void apply_type_policy(eprosima::fastdds::dds::TopicDataType& support) {
  // Announce the TypeInformation (type identifiers) but not the full
  // TypeObject: a Fast DDS 2.9 peer that receives the TypeObject of a type
  // with an array or sequence of structs/enums (Skeleton, ComponentStatus)
  // and has not registered it itself crashes (eProsima/Fast-DDS#3296).
  // See docs/type-information.md for the measured trade-off.
  support.auto_fill_type_information(true);
  support.auto_fill_type_object(false);
}

void apply_type_policy(eprosima::fastdds::dds::DomainParticipantQos& qos) {
  // Off by default in Fast DDS 2.9 and not settable from XML.
  qos.wire_protocol().builtin.typelookup_config.use_server = true;
}

}  // namespace skelgraph::runtime
