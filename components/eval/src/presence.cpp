#include "skelgraph/eval/presence.hpp"

#include <algorithm>
#include <cmath>

namespace skelgraph::eval {

namespace {

double horizontal(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::hypot(a.x() - b.x(), a.z() - b.z());
}

bool people_topic(const std::string& topic) {
  return topic == "skelgraph/skeleton/fused" || topic == "skelgraph/skeleton/truth" ||
         topic == "skelgraph/gesture/state" || topic == "skelgraph/skeleton/raw";
}

// {median, p95, max} in ms of a list of ns, null when empty.
nlohmann::json spread_ms(std::vector<std::int64_t> v) {
  if (v.empty()) return nullptr;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    return static_cast<double>(v[static_cast<std::size_t>(std::llround(q * static_cast<double>(v.size() - 1)))]) * 1e-6;
  };
  return {{"median", at(0.5)}, {"p95", at(0.95)}, {"max", at(1.0)}};
}

}  // namespace

Presence::Presence(PresenceOptions options) : o_(options) {}

void Presence::pose(const std::string& sensor, const Eigen::Isometry3d& world_from_sensor) { poses_[sensor] = world_from_sensor; }

std::optional<std::uint32_t> Presence::nearest(const Eigen::Vector3d& torso) const {
  std::optional<std::uint32_t> best;
  double best_d = o_.match_m;
  for (const auto& [id, p] : people_) {
    if (p.left_ns) continue;
    const double d = horizontal(p.torso, torso);
    if (d < best_d) {
      best_d = d;
      best = id;
    }
  }
  return best;
}

std::size_t Presence::people_there(std::int64_t t_ns) const {
  return static_cast<std::size_t>(std::count_if(people_.begin(), people_.end(), [&](const auto& kv) {
    return !kv.second.left_ns || t_ns - *kv.second.left_ns <= o_.linger_ns;
  }));
}

void Presence::truth(const skeleton::Skeleton& world, std::int64_t t_ns) {
  auto& p = people_[world.person_id];
  if (p.first_ns == 0) p.first_ns = t_ns;
  p.last_ns = t_ns;
  p.left_ns.reset();  // (an id used again: the same person back)
  p.torso = world[skeleton::JointId::Torso].position;
}

void Presence::truth_gone(std::uint32_t person, std::int64_t t_ns) {
  const auto it = people_.find(person);
  if (it != people_.end()) it->second.left_ns = t_ns;
}

void Presence::raw(const skeleton::Skeleton& s, std::int64_t t_ns) {
  const auto pose = poses_.find(s.sensor_id);
  const auto c = skeleton::centre_of(s);
  if (pose == poses_.end()) {
    ++raw_without_pose_;
    return;
  }
  auto& st = raw_[{s.sensor_id, s.person_id}];
  st.last_ns = t_ns;
  if (!c) return;
  // Near someone: shows them. Else (a tracker's ghost of someone who walked
  // away) it stays theirs, without counting as showing them.
  if (const auto who = nearest(pose->second * *c)) {
    st.person = who;
    people_[*who].tracked_until_ns = t_ns + o_.fresh_ns;
  }
}

void Presence::raw_gone(const std::string& sensor, std::uint32_t person, std::int64_t t_ns) {
  const auto it = raw_.find({sensor, person});
  if (it == raw_.end()) return;
  if (it->second.person) {
    auto& p = people_[*it->second.person];
    p.inputs_gone_ns = std::max(p.inputs_gone_ns.value_or(t_ns), t_ns);
  }
  raw_.erase(it);
}

void Presence::fused(const skeleton::Skeleton& s, std::int64_t t_ns) {
  const std::pair<std::string, std::uint32_t> key{s.sensor_id, s.person_id};
  auto& st = fused_[key];
  st.last_ns = t_ns;
  const auto c = skeleton::centre_of(s);
  if (!c) return;
  const auto who = nearest(*c);
  if (!who) return;  // (stays whose it was, as a raw stream does)
  st.person = who;
  auto& p = people_[*who];
  p.shown_until_ns = t_ns + o_.fresh_ns;
  p.fused_ids.insert(key);
}

void Presence::fused_gone(const std::string& stream, std::uint32_t person, std::int64_t t_ns) {
  const std::pair<std::string, std::uint32_t> key{stream, person};
  fused_gone_[key] = t_ns;
  const auto it = fused_.find(key);
  if (it == fused_.end()) return;
  if (it->second.person) {
    auto& p = people_[*it->second.person];
    p.fused_gone_ns = std::max(p.fused_gone_ns.value_or(t_ns), t_ns);
  }
  fused_.erase(it);
}

void Presence::output(const std::string& component, const std::string& topic, std::uint64_t failed_writes,
                      std::uint32_t instances, std::int64_t t_ns) {
  auto& o = outputs_[{component, topic}];
  o.failed = failed_writes;
  o.instances = instances;
  o.max_instances = std::max(o.max_instances, instances);
  if (!people_topic(topic)) return;
  o.bounded = true;
  auto bound = static_cast<long long>(people_there(t_ns));
  if (topic == "skelgraph/skeleton/raw") bound *= static_cast<long long>(std::max<std::size_t>(1, poses_.size()));
  o.max_excess = std::max(o.max_excess, static_cast<long long>(instances) - bound);
}

void Presence::sample(std::int64_t t_ns) {
  const double dt = last_sample_ns_ == 0 ? 0.0 : std::min(1.0, static_cast<double>(t_ns - last_sample_ns_) * 1e-9);
  last_sample_ns_ = t_ns;
  if (dt <= 0.0) return;
  for (auto& [id, p] : people_) {
    if (p.left_ns || t_ns - p.last_ns > o_.fresh_ns) continue;
    p.present_s += dt;
    if (p.tracked_until_ns < t_ns) continue;
    p.tracked_s += dt;
    if (p.shown_until_ns >= t_ns) p.shown_s += dt;
  }
}

std::size_t Presence::people_left() const {
  return static_cast<std::size_t>(
      std::count_if(people_.begin(), people_.end(), [](const auto& kv) { return kv.second.left_ns.has_value(); }));
}

std::uint64_t Presence::failed_writes() const {
  std::uint64_t n = 0;
  for (const auto& [key, o] : outputs_) n += o.failed;
  return n;
}

nlohmann::json Presence::report(bool people) const {
  double present = 0, tracked = 0, shown = 0;
  std::vector<double> ratios;
  std::size_t never_tracked = 0, never_shown = 0, below_90 = 0;
  std::vector<std::int64_t> graph_ns, truth_ns;
  std::size_t departures = 0, seen = 0, late = 0, still_shown = 0, unseen = 0;
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [id, p] : people_) {
    present += p.present_s;
    tracked += p.tracked_s;
    shown += p.shown_s;
    if (p.tracked_s <= 0) ++never_tracked;
    if (p.fused_ids.empty()) ++never_shown;
    if (p.tracked_s >= 2.0) {
      ratios.push_back(p.shown_s / p.tracked_s);
      if (ratios.back() < 0.9) ++below_90;
    }
    nlohmann::json row = {{"id", id},
                          {"present_s", p.present_s},
                          {"tracked_s", p.tracked_s},
                          {"shown_s", p.shown_s},
                          {"fused_ids", p.fused_ids.size()}};
    if (p.left_ns && !p.fused_ids.empty()) {
      ++departures;
      // Still shown: a fused instance that showed them is alive and still on them.
      const bool alive = std::any_of(p.fused_ids.begin(), p.fused_ids.end(), [&](const auto& key) {
        const auto it = fused_.find(key);
        return it != fused_.end() && it->second.person == id;
      });
      if (alive) {
        ++still_shown;
      } else if (p.fused_gone_ns) {
        ++seen;
        truth_ns.push_back(*p.fused_gone_ns - *p.left_ns);
        row["departure_after_truth_ms"] = static_cast<double>(*p.fused_gone_ns - *p.left_ns) * 1e-6;
        if (p.inputs_gone_ns) {
          const auto d = std::max<std::int64_t>(0, *p.fused_gone_ns - *p.inputs_gone_ns);
          graph_ns.push_back(d);
          if (d > o_.departure_limit_ns) ++late;
          row["departure_after_inputs_ms"] = static_cast<double>(d) * 1e-6;
        }
      } else {
        ++unseen;  // its fused instances followed someone else, or were never disposed while we listened
      }
    }
    if (people) list.push_back(std::move(row));
  }
  std::sort(ratios.begin(), ratios.end());
  std::size_t fused_alive = fused_.size();
  nlohmann::json outs = nlohmann::json::array();
  for (const auto& [key, o] : outputs_) {
    nlohmann::json j = {{"component", key.first}, {"topic", key.second},         {"failed_writes", o.failed},
                        {"instances", o.instances}, {"max_instances", o.max_instances}};
    if (o.bounded) j["max_instances_over_people"] = o.max_excess;
    outs.push_back(std::move(j));
  }
  nlohmann::json out = {
      {"people",
       {{"seen", people_.size()},
        {"left", people_left()},
        {"there_now", people_.size() - people_left()},
        {"never_tracked", never_tracked},
        {"never_shown", never_shown}}},
      {"completeness",
       {{"present_s", present},
        {"tracked_s", tracked},
        {"shown_s", shown},
        {"shown_of_tracked", tracked > 0 ? shown / tracked : 0.0},
        {"people_scored", ratios.size()},
        {"min_person", ratios.empty() ? nlohmann::json(nullptr) : nlohmann::json(ratios.front())},
        {"median_person", ratios.empty() ? nlohmann::json(nullptr) : nlohmann::json(ratios[ratios.size() / 2])},
        {"people_below_90_percent", below_90}}},
      {"departures",
       {{"people", departures},
        {"seen", seen},
        {"late", late},
        {"still_shown", still_shown},
        {"not_seen", unseen},
        {"after_inputs_ms", spread_ms(graph_ns)},
        {"after_truth_ms", spread_ms(truth_ns)},
        {"limit_ms", static_cast<double>(o_.departure_limit_ns) * 1e-6}}},
      {"fused", {{"instances_seen", fused_alive + fused_gone_.size()}, {"disposed", fused_gone_.size()}, {"alive", fused_alive}}},
      {"raw", {{"alive", raw_.size()}, {"without_pose", raw_without_pose_}}},
      {"failed_writes", failed_writes()},
      {"outputs", outs}};
  if (people) out["people_list"] = std::move(list);
  return out;
}

}  // namespace skelgraph::eval
