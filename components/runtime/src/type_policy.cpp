#include "skelgraph/runtime/type_policy.hpp"

#include <mutex>

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <skelgraphTypeObject.h>

namespace skelgraph::runtime {

void register_type_objects() {
  static std::once_flag once;
  std::call_once(once, [] { registerskelgraphTypes(); });
}

void apply_type_policy(eprosima::fastdds::dds::TopicDataType& support) {
  // Announce the TypeInformation (type identifiers) but not the full
  // TypeObject: see docs/type-information.md for the measured trade-off.
  support.auto_fill_type_information(true);
  support.auto_fill_type_object(false);
}

}  // namespace skelgraph::runtime
