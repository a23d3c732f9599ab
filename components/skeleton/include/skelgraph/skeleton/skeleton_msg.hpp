#pragma once
// Conversion between the canonical skeleton and the wire type (adapters only).

#include "skelgraph/msg/messages.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::skeleton {

msg::Skeleton to_msg(const Skeleton& s);
Skeleton from_msg(const msg::Skeleton& m);

msg::SensorPose to_msg(const SensorPose& p);
SensorPose from_msg(const msg::SensorPose& m);

}  // namespace skelgraph::skeleton
