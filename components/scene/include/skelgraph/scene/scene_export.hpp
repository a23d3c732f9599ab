#pragma once
// A recording with the scene added: every message of the input copied as it
// is (schemas, channels, metadata; a scene it already has is left out and
// made again), plus the SceneBuilder's output on
// skelgraph/scene/update (foxglove::SceneUpdate) and
// skelgraph/scene/transforms (foxglove::FrameTransform), both `cdr` with the
// schemas' OMG IDL from @foxglove/schemas.
#include <cstdint>
#include <functional>
#include <map>
#include <string_view>
#include <string>
#include <vector>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/recording/session_recorder.hpp"
#include "skelgraph/scene/scene.hpp"

namespace skelgraph::scene {

inline constexpr const char* kSceneTopic = "skelgraph/scene/update";
inline constexpr const char* kTransformTopic = "skelgraph/scene/transforms";

struct ExportReport {
  std::uint64_t copied = 0;       // input messages written again
  std::uint64_t skeletons = 0, poses = 0, pointing = 0, robot_states = 0, safety = 0;  // what went into the scene
  std::uint64_t updates = 0, entities = 0, transforms = 0;                // what came out
  std::uint64_t undecodable = 0;  // messages on a known topic that did not decode (left out of the scene)
  std::vector<std::string> unplaced;  // frames without a pose, drawn at the world's origin
};

// Adds the scene to an MCAP file being written: give it every recorded
// sample (any topic; those the scene uses are decoded), in log-time order, and
// it writes the SceneBuilder's output to the same writer. What the exporter
// and the recorder (its `scene` parameter) both use.
class SceneTap : public recording::RecordTap {
 public:
  explicit SceneTap(SceneOptions options = {}) : scene_(options) {}
  void add(mcap::Writer& w, const std::string& topic, const std::string& type_name, std::string_view cdr,
           std::int64_t log_ns) override;
  void finish(mcap::Writer& w) override;  // the last tick, and the frames without a pose into the report
  const ExportReport& report() const { return r_; }

 private:
  void emit(mcap::Writer& w, std::vector<Output> done);
  template <class T>
  void write(mcap::Writer& w, const std::string& topic, const T& value, std::int64_t log_ns);
  SceneBuilder scene_;
  ExportReport r_;
  std::map<std::string, std::uint16_t> channels_;
  std::map<std::uint16_t, std::uint32_t> sequence_;
};

// Throws mcap::McapError for an unreadable input or an unwritable output.
// `progress(done, total)` every few thousand messages.
ExportReport export_scene(const std::string& in_path, const std::string& out_path, const SceneOptions& options = {},
                          mcap::WriterOptions writer = {},
                          const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace skelgraph::scene
