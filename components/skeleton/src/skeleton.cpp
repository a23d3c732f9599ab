#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::skeleton {

namespace {
constexpr const char* kNames[kJointCount] = {"head",       "neck",          "torso",       "left_shoulder",
                                              "left_elbow", "left_hand",     "right_shoulder", "right_elbow",
                                              "right_hand", "left_hip",      "left_knee",   "left_foot",
                                              "right_hip",  "right_knee",    "right_foot"};
}  // namespace

const char* joint_name(JointId id) {
  const auto i = static_cast<std::size_t>(id);
  return i < kJointCount ? kNames[i] : "unknown";
}

std::optional<JointId> joint_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kJointCount; ++i) {
    if (name == kNames[i]) return joint_at(i);
  }
  return std::nullopt;
}

}  // namespace skelgraph::skeleton
