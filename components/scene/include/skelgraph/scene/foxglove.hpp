#pragma once
// The part of Foxglove's message schemas (@foxglove/schemas) that scene
// recordings use, as plain structs, and their CDR encoding (XCDR1, little
// endian, with the 4-byte encapsulation header: MCAP's `cdr` message
// encoding). Fields are in the schemas' order; the schema text itself is not
// typed here but written by the build from the npm package (schema_idl()).
// The npm test decodes what to_cdr writes against that schema. No DDS.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace skelgraph::scene {

struct Color {
  double r = 1, g = 1, b = 1, a = 1;
};

struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

struct Sphere {  // foxglove::SpherePrimitive
  Pose pose;
  Eigen::Vector3d size = Eigen::Vector3d::Constant(0.05);  // diameters
  Color color;
};

struct Cylinder {  // foxglove::CylinderPrimitive: along its z axis
  Pose pose;
  Eigen::Vector3d size = Eigen::Vector3d::Constant(0.1);
  double bottom_scale = 1, top_scale = 1;
  Color color;
};

struct Arrow {  // foxglove::ArrowPrimitive: along its x axis
  Pose pose;
  double shaft_length = 1, shaft_diameter = 0.02, head_length = 0.1, head_diameter = 0.05;
  Color color;
};

enum class LineType : std::uint32_t { Strip = 0, Loop = 1, List = 2 };

struct Line {  // foxglove::LinePrimitive
  LineType type = LineType::List;
  Pose pose;
  double thickness = 0.02;
  bool scale_invariant = false;
  std::vector<Eigen::Vector3d> points;
  Color color;
  std::vector<Color> colors;  // per point, or empty
  std::vector<std::uint32_t> indices;
};

struct Text {  // foxglove::TextPrimitive
  Pose pose;
  bool billboard = true;
  double font_size = 0.1;
  bool scale_invariant = false;
  Color color;
  std::string text;
};

struct Entity {  // foxglove::SceneEntity (cubes, triangles and models: none)
  std::int64_t stamp_ns = 0;
  std::string frame_id, id;
  std::int64_t lifetime_ns = 0;  // 0: until replaced
  bool frame_locked = false;
  std::vector<std::pair<std::string, std::string>> metadata;
  std::vector<Arrow> arrows;
  std::vector<Sphere> spheres;
  std::vector<Cylinder> cylinders;
  std::vector<Line> lines;
  std::vector<Text> texts;
};

struct SceneUpdate {  // foxglove::SceneUpdate (deletions: none; lifetimes retire entities)
  std::vector<Entity> entities;
};

struct FrameTransform {  // foxglove::FrameTransform: where `child` is in `parent`
  std::int64_t stamp_ns = 0;
  std::string parent, child;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

std::vector<std::uint8_t> to_cdr(const SceneUpdate& u);
std::vector<std::uint8_t> to_cdr(const FrameTransform& t);

// The schema name MCAP files give ("foxglove::SceneUpdate") and its OMG IDL,
// flattened (components/scene/schemas/write_idl.cjs, run by the build).
template <class T>
struct SchemaOf;
template <>
struct SchemaOf<SceneUpdate> {
  static constexpr const char* name = "foxglove::SceneUpdate";
};
template <>
struct SchemaOf<FrameTransform> {
  static constexpr const char* name = "foxglove::FrameTransform";
};
const std::string& schema_idl(const std::string& name);  // throws std::out_of_range for another name

}  // namespace skelgraph::scene
