#pragma once
// What type information our endpoints announce during discovery. One place,
// because it decides both whether DDS tools can show our types and whether a
// Fast DDS 2.9 peer survives discovering them (see docs/type-information.md).

namespace eprosima::fastdds::dds {
class DomainParticipantQos;
class TopicDataType;
}

namespace skelgraph::runtime {

// Registers the generated TypeObjects with Fast DDS's TypeObjectFactory (once).
void register_type_objects();
// Sets what `support` announces; applied to every generated type (make_type_support).
void apply_type_policy(eprosima::fastdds::dds::TopicDataType& support);
// Participant side: answers TypeLookup requests so tools can fetch our types.
void apply_type_policy(eprosima::fastdds::dds::DomainParticipantQos& qos);

}  // namespace skelgraph::runtime
