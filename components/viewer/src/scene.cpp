#include "skelgraph/viewer/scene.hpp"

#include <algorithm>
#include <cmath>


namespace skelgraph::viewer {

const char* kind_name(StreamKind k) {
  switch (k) {
    case StreamKind::Raw: return "raw";
    case StreamKind::Fused: return "fused";
    case StreamKind::Truth: return "truth";
  }
  return "raw";
}

StreamKind stream_kind(const std::string& sensor_id) {
  if (sensor_id == "fused") return StreamKind::Fused;
  if (sensor_id == "truth") return StreamKind::Truth;
  return StreamKind::Raw;
}

int joint_state(float confidence) {
  if (!(confidence > 0.0f)) return 0;  // also NaN
  return confidence >= 0.75f ? 2 : 1;
}

Scene::Scene(SceneOptions options) : o_(options) {}

namespace {
// Millimetres are plenty for a view and keep the messages small.
double mm(double v) { return std::round(v * 1000.0) / 1000.0; }
nlohmann::json vec(const Eigen::Vector3d& v) { return {mm(v.x()), mm(v.y()), mm(v.z())}; }
}  // namespace



void Scene::on_skeleton(const skeleton::Skeleton& s, std::int64_t now_ns) {
  const StreamKind kind = stream_kind(s.sensor_id);
  auto [it, added] = streams_.try_emplace(s.sensor_id, Stream{kind, runtime::RateStats(o_.rate_window_ns)});
  Stream& stream = it->second;
  stream.rate.add(now_ns);
  skeleton::Skeleton world = s;
  if (s.frame_id != "world") {
    const auto pose = poses_.find(s.sensor_id);
    if (pose == poses_.end()) {
      ++stream.unplaced;
      return;
    }
    for (auto& j : world.joints) {
      j.position = pose->second.pose * j.position;
      j.orientation = Eigen::Quaterniond(pose->second.pose.linear()) * j.orientation;
    }
    world.frame_id = "world";
  }
  skeletons_[{s.sensor_id, s.person_id}] = Held{std::move(world), kind, now_ns};
}

void Scene::on_gone(const std::string& sensor_id, std::uint32_t person_id) { skeletons_.erase({sensor_id, person_id}); }

bool Scene::on_pose(const skeleton::SensorPose& p) {
  if (p.frame_id != "world") return false;
  poses_[p.sensor_id] = p;
  return true;
}

void Scene::on_gesture(nlohmann::json event, std::int64_t now_ns) { gestures_.emplace_back(now_ns, std::move(event)); }

void Scene::on_status(const std::string& component, nlohmann::json status, std::int64_t now_ns) {
  status_[component] = {now_ns, std::move(status)};
}

void Scene::on_player(const std::string& player, nlohmann::json state) { players_[player] = std::move(state); }

void Scene::on_robot(nlohmann::json state, std::int64_t now_ns) {
  const auto id = state.value("robot_id", std::string());
  robots_[id] = {now_ns, std::move(state)};
}

void Scene::on_safety(nlohmann::json status, std::int64_t now_ns) {
  const auto id = status.value("robot_id", std::string());
  safety_[id] = {now_ns, std::move(status)};
}

nlohmann::json Scene::frame(std::int64_t now_ns) {
  nlohmann::json skeletons = nlohmann::json::array();
  for (auto it = skeletons_.begin(); it != skeletons_.end();) {
    if (now_ns - it->second.received_ns > o_.max_age_ns) {
      it = skeletons_.erase(it);
      continue;
    }
    const auto& s = it->second.world;
    nlohmann::json joints = nlohmann::json::array();
    for (const auto& j : s.joints) {
      const int state = joint_state(j.confidence);
      if (state == 0) joints.push_back({0, 0, 0, 0, 0});
      else joints.push_back({mm(j.position.x()), mm(j.position.y()), mm(j.position.z()), state, mm(skeleton::radius_95(j))});
    }
    skeletons.push_back({{"stream", s.sensor_id},
                         {"kind", kind_name(it->second.kind)},
                         {"person", s.person_id},
                         {"frame", s.frame_number},
                         {"stamp_ns", s.stamp_ns},
                         {"age_ms", (now_ns - it->second.received_ns) / 1'000'000},
                         {"joints", std::move(joints)}});
    ++it;
  }
  nlohmann::json streams = nlohmann::json::object();
  nlohmann::json unplaced = nlohmann::json::array();
  for (auto& [id, st] : streams_) {
    st.rate.expire(now_ns);
    streams[id] = {{"kind", kind_name(st.kind)}, {"rate_hz", std::round(st.rate.summary().rate_hz * 10.0) / 10.0},
                   {"samples", st.rate.total()}, {"unplaced", st.unplaced}};
    if (st.kind == StreamKind::Raw && !poses_.count(id) && st.unplaced > 0) unplaced.push_back(id);
  }
  nlohmann::json sensors = nlohmann::json::array();
  for (const auto& [id, p] : poses_) {
    const Eigen::Quaterniond q(p.pose.linear());
    sensors.push_back({{"id", id},
                       {"position", vec(p.pose.translation())},
                       {"rotation", {q.w(), q.x(), q.y(), q.z()}},
                       {"method", p.method},
                       {"rms_residual_m", p.rms_residual_m}});
  }
  nlohmann::json gestures = nlohmann::json::array();
  gestures_.erase(std::remove_if(gestures_.begin(), gestures_.end(),
                                 [&](const auto& g) { return now_ns - g.first > o_.gesture_hold_ns; }),
                  gestures_.end());
  for (const auto& [t, g] : gestures_) {
    nlohmann::json e = g;
    e["age_ms"] = (now_ns - t) / 1'000'000;
    gestures.push_back(std::move(e));
  }
  nlohmann::json status = nlohmann::json::array();
  for (auto it = status_.begin(); it != status_.end();) {
    if (now_ns - it->second.first > o_.status_max_age_ns) {
      it = status_.erase(it);
      continue;
    }
    status.push_back(it->second.second);
    ++it;
  }
  nlohmann::json players = nlohmann::json::array();
  for (const auto& [name, p] : players_) players.push_back(p);
  nlohmann::json robots = nlohmann::json::array();
  const auto mm3 = [](const nlohmann::json& v) { return nlohmann::json{mm(v["x"].get<double>()), mm(v["y"].get<double>()), mm(v["z"].get<double>())}; };
  for (auto it = robots_.begin(); it != robots_.end();) {
    if (now_ns - it->second.first > o_.status_max_age_ns) {
      it = robots_.erase(it);
      continue;
    }
    const auto& r = it->second.second;
    nlohmann::json capsules = nlohmann::json::array();
    for (const auto& c : r["capsules"]) {
      auto row = mm3(c["a"]);
      for (const auto& v : mm3(c["b"])) row.push_back(v);
      row.push_back(mm(c["radius"].get<double>()));
      capsules.push_back(std::move(row));
    }
    nlohmann::json safety;
    const auto s = safety_.find(it->first);
    if (s != safety_.end() && now_ns - s->second.first <= o_.status_max_age_ns) {
      const auto& v = s->second.second;
      safety = {{"state", v["state"]},           {"separation_m", v["separation_m"]}, {"protective_m", v["protective_m"]},
                {"person_id", v["person_id"]},   {"body_part", v["body_part"]},       {"robot_part", v["robot_part"]},
                {"reason", v["reason"]}};
    }
    robots.push_back({{"id", it->first},
                      {"capsules", std::move(capsules)},
                      {"tool", mm3(r["tool_position"])},
                      {"speed_scale", r["speed_scale"]},
                      {"stopped", r["protective_stop"]},
                      {"safety", std::move(safety)}});
    ++it;
  }
  return {{"type", "frame"},
          {"seq", ++seq_},
          {"skeletons", std::move(skeletons)},
          {"sensors", std::move(sensors)},
          {"frustum", {{"fov_h_deg", o_.fov_h_deg}, {"fov_v_deg", o_.fov_v_deg}, {"near_m", o_.near_m}, {"far_m", o_.far_m}}},
          {"streams", std::move(streams)},
          {"unplaced", std::move(unplaced)},
          {"gestures", std::move(gestures)},
          {"status", std::move(status)},
          {"players", std::move(players)},
          {"robots", std::move(robots)}};
}

}  // namespace skelgraph::viewer
