#include "skelgraph/scene/scene_export.hpp"

#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::scene {

namespace {

Eigen::Vector3d vec(const msg::Vec3& v) { return {v.x(), v.y(), v.z()}; }

std::optional<Stream> stream_of(const std::string& topic) {
  if (topic == runtime::topics::kSkeletonRaw.name) return Stream::Raw;
  if (topic == runtime::topics::kSkeletonFused.name) return Stream::Fused;
  if (topic == runtime::topics::kSkeletonTruth.name) return Stream::Truth;
  return std::nullopt;
}

}  // namespace

template <class T>
void SceneTap::write(mcap::Writer& w, const std::string& topic, const T& value, std::int64_t log_ns) {
  auto& ch = channels_[topic];
  if (ch == 0) {
    const auto schema = w.add_schema(SchemaOf<T>::name, "omgidl", schema_idl(SchemaOf<T>::name));
    ch = w.add_channel(schema, topic, "cdr");
  }
  const auto bytes = to_cdr(value);
  mcap::Message m;
  m.channel_id = ch;
  m.sequence = ++sequence_[ch];
  m.log_time = m.publish_time = static_cast<std::uint64_t>(std::max<std::int64_t>(0, log_ns));
  m.data = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  w.write(m);
}

void SceneTap::emit(mcap::Writer& w, std::vector<Output> done) {
  for (auto& o : done) {
    if (o.is_transform) {
      write(w, kTransformTopic, o.transform, o.log_ns);
      ++r_.transforms;
    } else {
      r_.entities += o.update.entities.size();
      write(w, kSceneTopic, o.update, o.log_ns);
      ++r_.updates;
    }
  }
}

void SceneTap::add(mcap::Writer& w, const std::string& topic, const std::string& type_name, std::string_view cdr,
                   std::int64_t log_ns) {
  emit(w, scene_.take(log_ns));
  const auto* data = cdr.data();
  const auto size = cdr.size();
  try {
    if (const auto stream = stream_of(topic); stream && type_name == msg::MessageTraits<msg::Skeleton>::name) {
      scene_.add_skeleton(*stream, skeleton::from_msg(msg::from_cdr<msg::Skeleton>(data, size)), log_ns);
      ++r_.skeletons;
    } else if (topic == runtime::topics::kCalibration.name && type_name == msg::MessageTraits<msg::SensorPose>::name) {
      scene_.add_pose(skeleton::from_msg(msg::from_cdr<msg::SensorPose>(data, size)), log_ns);
      ++r_.poses;
    } else if (topic == runtime::topics::kGestureEvent.name && type_name == msg::MessageTraits<msg::GestureEvent>::name) {
      const auto e = msg::from_cdr<msg::GestureEvent>(data, size);
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
      scene_.add_pointing(p, log_ns);
      ++r_.pointing;
    } else if (topic == runtime::topics::kRobotState.name && type_name == msg::MessageTraits<msg::RobotState>::name) {
      const auto s = msg::from_cdr<msg::RobotState>(data, size);
      std::vector<Capsule> caps;
      for (const auto& c : s.capsules()) caps.push_back({vec(c.a()), vec(c.b()), c.radius(), c.name().to_string()});
      scene_.add_robot(s.robot_id().to_string(), caps, s.protective_stop(), log_ns);
      ++r_.robot_states;
    } else if (topic == runtime::topics::kSafety.name && type_name == msg::MessageTraits<msg::SafetyStatus>::name) {
      const auto m = msg::from_cdr<msg::SafetyStatus>(data, size);
      Safety s;
      s.robot_id = m.robot_id().to_string();
      s.state = m.state() == msg::SAFETY_PROTECTIVE_STOP ? SafetyState::ProtectiveStop
                : m.state() == msg::SAFETY_REDUCED       ? SafetyState::Reduced
                                                         : SafetyState::Run;
      s.speed_scale = m.speed_scale();
      s.separation_m = m.separation_m();
      s.person_id = m.person_id();
      s.body_part = m.body_part().to_string();
      s.reason = m.reason().to_string();
      scene_.add_safety(s, log_ns);
      ++r_.safety;
    }
  } catch (const std::runtime_error&) {
    ++r_.undecodable;
  }
}

void SceneTap::finish(mcap::Writer& w) {
  emit(w, scene_.finish());
  r_.unplaced.assign(scene_.unplaced().begin(), scene_.unplaced().end());
}

ExportReport export_scene(const std::string& in_path, const std::string& out_path, const SceneOptions& options,
                          mcap::WriterOptions writer, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const mcap::Reader reader(in_path);
  const auto summary = reader.summary();
  if (writer.profile.empty()) writer.profile = summary.profile;
  mcap::Writer out(out_path, std::move(writer));
  SceneTap tap(options);
  std::uint64_t seen = 0;
  const auto copied = mcap::copy_messages(
      reader, out,
      [](const mcap::Channel& ch) { return ch.topic != kSceneTopic && ch.topic != kTransformTopic; },  // a live scene: made again
      [&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
        if (progress && ++seen % 5000 == 0) progress(seen, summary.message_count);
        if (schema && ch.message_encoding == "cdr") tap.add(out, ch.topic, schema->name, m.data, static_cast<std::int64_t>(m.log_time));
      });
  tap.finish(out);
  if (progress) progress(copied, summary.message_count);
  out.close();
  auto r = tap.report();
  r.copied = copied;
  return r;
}

}  // namespace skelgraph::scene
