#include "skelgraph/calib/inputs.hpp"

#include <algorithm>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/messages.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::calib {

namespace {
// Every message of an MCAP file with a schema: f(topic, schema name, log time, CDR bytes, size).
template <class F>
void for_each_message(const std::string& path, F&& f) {
  try {
    const mcap::Reader reader(path);
    reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
      if (schema == nullptr) return;
      f(ch.topic, schema->name, static_cast<std::int64_t>(m.log_time), reinterpret_cast<const std::uint8_t*>(m.data.data()),
        m.data.size());
    });
  } catch (const mcap::McapError& e) {
    throw InputError(e.what());
  }
}
}  // namespace

SkeletonInput read_skeleton_input(const std::string& path, const std::string& format, bool skip_bad_lines) {
  SkeletonInput in;
  if (!format.empty()) {
    playback::Recording rec;
    playback::ReadOptions read;
    read.on_error = skip_bad_lines ? playback::ReadOptions::OnError::Skip : playback::ReadOptions::OnError::Stop;
    try {
      const auto f = playback::format_from_name(format);
      if (!f) throw InputError("unknown format '" + format + "'");
      rec = playback::read_recording(*f, path, read);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(e.what());
    }
    in.skipped_note = playback::skipped_summary(rec);
    for (const auto& s : rec.frames) in.by_sensor[s.sensor_id].push_back({s.stamp_ns, s});
    return in;
  }
  for_each_message(path, [&](const std::string& topic, const std::string& type, std::int64_t t, const std::uint8_t* bytes,
                              std::size_t size) {
    if (topic == runtime::topics::kSkeletonRaw.name && type == msg::MessageTraits<msg::Skeleton>::name) {
      auto s = skeleton::from_msg(msg::from_cdr<msg::Skeleton>(bytes, size));
      in.by_sensor[s.sensor_id].push_back({t, std::move(s)});
    } else if (topic == runtime::topics::kCalibration.name && type == msg::MessageTraits<msg::SensorPose>::name) {
      const auto p = skeleton::from_msg(msg::from_cdr<msg::SensorPose>(bytes, size));
      if (p.frame_id == "world") in.poses[p.sensor_id] = p.pose;
    }
  });
  return in;
}

HandInput read_hand_input(const std::string& path, const std::vector<skeleton::JointId>& joints) {
  HandInput in;
  for_each_message(path, [&](const std::string& topic, const std::string& type, std::int64_t t, const std::uint8_t* bytes,
                              std::size_t size) {
    if (topic == runtime::topics::kRobotState.name && type == msg::MessageTraits<msg::RobotState>::name) {
      const auto st = msg::from_cdr<msg::RobotState>(bytes, size);
      const auto& p = st.tool_position();
      in.tool.push_back({t, {p.x(), p.y(), p.z()}});
      ++in.states;
    } else if (topic == runtime::topics::kSkeletonRaw.name && type == msg::MessageTraits<msg::Skeleton>::name) {
      const auto s = skeleton::from_msg(msg::from_cdr<msg::Skeleton>(bytes, size));
      for (std::size_t k = 0; k < joints.size(); ++k) {
        const auto& j = s[joints[k]];
        if (j.confidence < 0.5f) continue;  // inferred: not where the hand is
        in.hands[s.sensor_id][{s.person_id, static_cast<int>(k)}].push_back({t, j.position});
      }
    }
  });
  const auto by_time = [](const TimedPoint& a, const TimedPoint& b) { return a.t_ns < b.t_ns; };
  std::sort(in.tool.begin(), in.tool.end(), by_time);
  for (auto& [s, people] : in.hands) {
    for (auto& [id, pts] : people) std::sort(pts.begin(), pts.end(), by_time);
  }
  if (in.states == 0) throw InputError(path + ": no skelgraph/robot/state messages (record the robot with the people)");
  if (in.hands.empty()) throw InputError(path + ": no skelgraph/skeleton/raw skeletons with a tracked hand");
  return in;
}

}  // namespace skelgraph::calib
