#include "skelgraph/scene/scene_export.hpp"

#include <map>

#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::scene {

namespace {

Eigen::Vector3d vec(const msg::Vec3& v) { return {v.x(), v.y(), v.z()}; }

class Out {
 public:
  Out(const std::string& path, mcap::WriterOptions o) : w_(path, std::move(o)) {}
  mcap::Writer& writer() { return w_; }
  template <class T>
  void write(const std::string& topic, const T& value, std::int64_t log_ns) {
    auto& ch = channels_[topic];
    if (ch == 0) {
      const auto schema = w_.add_schema(SchemaOf<T>::name, "omgidl", schema_idl(SchemaOf<T>::name));
      ch = w_.add_channel(schema, topic, "cdr");
    }
    const auto bytes = to_cdr(value);
    mcap::Message m;
    m.channel_id = ch;
    m.sequence = ++sequence_[ch];
    m.log_time = m.publish_time = static_cast<std::uint64_t>(std::max<std::int64_t>(0, log_ns));
    m.data = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    w_.write(m);
  }

 private:
  mcap::Writer w_;
  std::map<std::string, std::uint16_t> channels_;
  std::map<std::uint16_t, std::uint32_t> sequence_;
};

}  // namespace

ExportReport export_scene(const std::string& in_path, const std::string& out_path, const SceneOptions& options,
                          mcap::WriterOptions writer, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const mcap::Reader reader(in_path);
  const auto summary = reader.summary();
  if (writer.profile.empty()) writer.profile = summary.profile;
  Out out(out_path, std::move(writer));
  ExportReport r;
  SceneBuilder scene(options);
  const auto emit = [&](std::vector<Output> done) {
    for (auto& o : done) {
      if (o.is_transform) {
        out.write(kTransformTopic, o.transform, o.log_ns);
        ++r.transforms;
      } else {
        r.entities += o.update.entities.size();
        out.write(kSceneTopic, o.update, o.log_ns);
        ++r.updates;
      }
    }
  };
  std::map<std::uint16_t, std::uint16_t> channel_map;  // input channel -> output channel
  for (const auto& m : summary.metadata) out.writer().write_metadata(m);
  const auto stream_of = [](const std::string& topic) -> std::optional<Stream> {
    if (topic == runtime::topics::kSkeletonRaw.name) return Stream::Raw;
    if (topic == runtime::topics::kSkeletonFused.name) return Stream::Fused;
    if (topic == runtime::topics::kSkeletonTruth.name) return Stream::Truth;
    return std::nullopt;
  };
  reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
    auto& mapped = channel_map[ch.id];
    if (mapped == 0) {
      const auto sid = schema ? out.writer().add_schema(schema->name, schema->encoding, schema->data) : std::uint16_t{0};
      mapped = out.writer().add_channel(sid, ch.topic, ch.message_encoding, ch.metadata);
    }
    mcap::Message copy = m;
    copy.channel_id = mapped;
    out.writer().write(copy);
    ++r.copied;
    if (progress && r.copied % 5000 == 0) progress(r.copied, summary.message_count);
    const auto log_ns = static_cast<std::int64_t>(m.log_time);
    emit(scene.take(log_ns));
    if (!schema || ch.message_encoding != "cdr") return;
    try {
      if (const auto stream = stream_of(ch.topic); stream && schema->name == msg::MessageTraits<msg::Skeleton>::name) {
        scene.add_skeleton(*stream, skeleton::from_msg(msg::from_cdr<msg::Skeleton>(m.data.data(), m.data.size())), log_ns);
        ++r.skeletons;
      } else if (ch.topic == runtime::topics::kCalibration.name && schema->name == msg::MessageTraits<msg::SensorPose>::name) {
        scene.add_pose(skeleton::from_msg(msg::from_cdr<msg::SensorPose>(m.data.data(), m.data.size())), log_ns);
        ++r.poses;
      } else if (ch.topic == runtime::topics::kGestureEvent.name &&
                 schema->name == msg::MessageTraits<msg::GestureEvent>::name) {
        const auto e = msg::from_cdr<msg::GestureEvent>(m.data.data(), m.data.size());
        if (!e.has_ray()) return;
        Pointing p;
        p.person_id = e.person_id();
        p.label = e.label().to_string();
        p.arm = e.arm().to_string();
        p.origin = vec(e.ray_origin());
        p.direction = vec(e.ray_direction());
        p.has_target = e.has_target();
        p.target = vec(e.target());
        p.confidence = e.confidence();
        scene.add_pointing(p, log_ns);
        ++r.pointing;
      } else if (ch.topic == runtime::topics::kRobotState.name && schema->name == msg::MessageTraits<msg::RobotState>::name) {
        const auto s = msg::from_cdr<msg::RobotState>(m.data.data(), m.data.size());
        std::vector<Capsule> caps;
        for (const auto& c : s.capsules()) caps.push_back({vec(c.a()), vec(c.b()), c.radius(), c.name().to_string()});
        scene.add_robot(s.robot_id().to_string(), caps, s.protective_stop(), log_ns);
        ++r.robot_states;
      }
    } catch (const std::runtime_error&) {
      ++r.undecodable;
    }
  });
  emit(scene.finish());
  r.unplaced.assign(scene.unplaced().begin(), scene.unplaced().end());
  if (progress) progress(r.copied, summary.message_count);
  out.writer().close();
  return r;
}

}  // namespace skelgraph::scene
