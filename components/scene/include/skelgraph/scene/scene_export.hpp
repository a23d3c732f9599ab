#pragma once
// A recording with the scene added: every message of the input copied as it
// is (schemas, channels, metadata), plus the SceneBuilder's output on
// skelgraph/scene/update (foxglove::SceneUpdate) and
// skelgraph/scene/transforms (foxglove::FrameTransform), both `cdr` with the
// schemas' OMG IDL from @foxglove/schemas.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/scene/scene.hpp"

namespace skelgraph::scene {

inline constexpr const char* kSceneTopic = "skelgraph/scene/update";
inline constexpr const char* kTransformTopic = "skelgraph/scene/transforms";

struct ExportReport {
  std::uint64_t copied = 0;       // input messages written again
  std::uint64_t skeletons = 0, poses = 0, pointing = 0, robot_states = 0;  // what went into the scene
  std::uint64_t updates = 0, entities = 0, transforms = 0;                // what came out
  std::uint64_t undecodable = 0;  // messages on a known topic that did not decode (left out of the scene)
  std::vector<std::string> unplaced;  // frames without a pose, drawn at the world's origin
};

// Throws mcap::McapError for an unreadable input or an unwritable output.
// `progress(done, total)` every few thousand messages.
ExportReport export_scene(const std::string& in_path, const std::string& out_path, const SceneOptions& options = {},
                          mcap::WriterOptions writer = {},
                          const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace skelgraph::scene
