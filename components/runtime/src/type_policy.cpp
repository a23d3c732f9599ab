#include "skelgraph/runtime/type_policy.hpp"

#include <mutex>
#include <stdexcept>
#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/attributes/PropertyPolicy.h>
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

bool apply_type_policy(eprosima::fastdds::dds::DomainParticipantQos& qos) {
  // Off by default in Fast DDS 2.9 and not settable from XML.
  qos.wire_protocol().builtin.typelookup_config.use_server = true;
  const std::string* v =
      eprosima::fastrtps::rtps::PropertyPolicyHelper::find_property(qos.properties(), "skelgraph.type_information");
  if (v == nullptr || *v == "on") return true;
  if (*v == "off") return false;
  throw std::runtime_error("DDS profile: property skelgraph.type_information must be 'on' or 'off', not '" + *v + "'");
}

void withhold_type_information(eprosima::fastdds::dds::TopicDataType& support) {
  support.auto_fill_type_information(false);
  support.auto_fill_type_object(false);
}

}  // namespace skelgraph::runtime
