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
// Returns whether the participant's types announce their TypeInformation: yes,
// unless the profile says otherwise with the participant property
// `skelgraph.type_information` = `off` (the *-interop profiles: Cyclone DDS
// 0.10 rejects Fast DDS 2.9's TypeInformation, so it cannot match endpoints
// that announce it; see docs/interop.md). Throws std::runtime_error for a
// value other than on/off.
bool apply_type_policy(eprosima::fastdds::dds::DomainParticipantQos& qos);
// For a participant that announces no type information (see above).
void withhold_type_information(eprosima::fastdds::dds::TopicDataType& support);

}  // namespace skelgraph::runtime
