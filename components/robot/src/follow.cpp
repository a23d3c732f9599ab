#include "skelgraph/robot/follow.hpp"

#include <limits>
#include <sstream>

namespace skelgraph::robot {

Follower::Follower(FollowParams params, Eigen::Vector3d robot_base_world) : p_(std::move(params)), base_(std::move(robot_base_world)) {}

FollowTarget Follower::step(const std::vector<skeleton::Skeleton>& people, std::int64_t now_ns) {
  FollowTarget out;
  const auto usable = [&](const skeleton::Skeleton& s) { return s[p_.joint].confidence >= skeleton::kTracked; };
  const skeleton::Skeleton* who = nullptr;
  if (followed_) {
    for (const auto& s : people) {
      if (s.person_id == *followed_) who = &s;
    }
  }
  if (who == nullptr) {
    // The person whose hand is nearest the workspace.
    double best = std::numeric_limits<double>::infinity();
    for (const auto& s : people) {
      if (!usable(s)) continue;
      const double d = p_.workspace.exteriorDistance(s[p_.joint].position);
      if (d < best) {
        best = d;
        who = &s;
      }
    }
  }
  if (who == nullptr) {
    followed_.reset();
    out.reason = people.empty() ? "nobody in the cell" : "no tracked hand";
    return out;
  }
  followed_ = who->person_id;
  out.person = who->person_id;
  const std::int64_t capture = who->capture_newest_ns != 0 ? who->capture_newest_ns : who->stamp_ns;
  const double age = static_cast<double>(now_ns - capture) * 1e-9;
  std::ostringstream why;
  if (!usable(*who)) {
    why << "person " << who->person_id << "'s hand not tracked";
  } else if (age > p_.max_age_s) {
    why << "person " << who->person_id << "'s data " << static_cast<int>(age * 1e3) << " ms old";
  }
  if (!why.str().empty()) {
    out.reason = why.str();
    return out;
  }
  const Eigen::Vector3d hand = (*who)[p_.joint].position;
  Eigen::Vector3d towards = base_ - hand;
  towards.y() = 0;
  if (towards.norm() < 1e-6) towards = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d target = hand + p_.standoff_m * towards.normalized();
  target = target.cwiseMax(p_.workspace.min()).cwiseMin(p_.workspace.max());
  out.hold = false;
  out.target = target;
  why << "following person " << who->person_id;
  out.reason = why.str();
  return out;
}

}  // namespace skelgraph::robot
