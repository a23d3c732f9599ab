#pragma once
// The generated wire types and a trait that ties each to its DDS type support.

#include <skelgraph.h>
#include <skelgraphPubSubTypes.h>

namespace skelgraph::msg {

template <class T>
struct MessageTraits;  // specialised below for every top-level wire type

#define SKELGRAPH_MESSAGE_TRAITS(Type)                       \
  template <>                                                \
  struct MessageTraits<Type> {                               \
    using PubSubType = Type##PubSubType;                     \
    static constexpr const char* name = "skelgraph::msg::" #Type; \
  };

SKELGRAPH_MESSAGE_TRAITS(Skeleton)
SKELGRAPH_MESSAGE_TRAITS(SyncCommand)
SKELGRAPH_MESSAGE_TRAITS(SyncControl)
SKELGRAPH_MESSAGE_TRAITS(SyncAck)
SKELGRAPH_MESSAGE_TRAITS(ClockOffset)
SKELGRAPH_MESSAGE_TRAITS(SensorPose)
SKELGRAPH_MESSAGE_TRAITS(DepthFrame)
SKELGRAPH_MESSAGE_TRAITS(GestureEvent)
SKELGRAPH_MESSAGE_TRAITS(GestureState)
SKELGRAPH_MESSAGE_TRAITS(PointCloud)
SKELGRAPH_MESSAGE_TRAITS(PlayControl)
SKELGRAPH_MESSAGE_TRAITS(PlayState)
SKELGRAPH_MESSAGE_TRAITS(ComponentStatus)
SKELGRAPH_MESSAGE_TRAITS(TickFrames)
SKELGRAPH_MESSAGE_TRAITS(SensorFrame)
SKELGRAPH_MESSAGE_TRAITS(RobotState)
SKELGRAPH_MESSAGE_TRAITS(RobotCommand)
SKELGRAPH_MESSAGE_TRAITS(SafetyStatus)

#undef SKELGRAPH_MESSAGE_TRAITS

// Canonical joint names, indexed by JointId (lower-case, as in launch files and JSON).
const char* joint_name(JointId id);

}  // namespace skelgraph::msg
