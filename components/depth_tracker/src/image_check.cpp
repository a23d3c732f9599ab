#include "skelgraph/depth_tracker/image_check.hpp"

#include <array>
#include <cmath>
#include <utility>

#include "skelgraph/depth_tracker/tracker.hpp"

namespace skelgraph::depth_tracker {

using skeleton::JointId;

std::vector<PersonOnImage> check_people(const depth::DepthImage& image, const std::vector<skeleton::Skeleton>& people,
                                        double on_person_m) {
  std::size_t nearest = 0;
  for (std::size_t k = 1; k < people.size(); ++k) {
    if (people[k][JointId::Torso].position.z() < people[nearest][JointId::Torso].position.z()) nearest = k;
  }
  std::vector<PersonOnImage> out;
  for (std::size_t k = 0; k < people.size(); ++k) {
    PersonOnImage p;
    p.person_id = people[k].person_id;
    p.nearest = k == nearest;
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      const auto& jt = people[k].joints[j];
      if (jt.confidence <= 0) continue;
      const bool on = on_surface(image, jt.position, on_person_m);
      p.on_person += on;
      p.joints.push_back({skeleton::joint_at(j), depth::project(image.intrinsics, jt.position), jt.confidence, on});
    }
    out.push_back(std::move(p));
  }
  return out;
}

void BoneSpreads::add(const skeleton::Skeleton& s) {
  static const std::array<std::pair<JointId, JointId>, 6> bones = {{{JointId::Neck, JointId::Head},
                                                                    {JointId::LeftShoulder, JointId::RightShoulder},
                                                                    {JointId::LeftShoulder, JointId::LeftElbow},
                                                                    {JointId::LeftElbow, JointId::LeftHand},
                                                                    {JointId::RightShoulder, JointId::RightElbow},
                                                                    {JointId::RightElbow, JointId::RightHand}}};
  for (const auto& [a, b] : bones) {
    if (s[a].confidence <= 0 || s[b].confidence <= 0) continue;
    lengths_[std::string(skeleton::joint_name(a)) + "-" + skeleton::joint_name(b)].push_back((s[a].position - s[b].position).norm());
  }
}

std::map<std::string, BoneSpread> BoneSpreads::summary() const {
  std::map<std::string, BoneSpread> out;
  for (const auto& [name, v] : lengths_) {
    double mean = 0, sq = 0;
    for (double x : v) mean += x;
    mean /= static_cast<double>(v.size());
    for (double x : v) sq += (x - mean) * (x - mean);
    out[name] = {v.size(), mean, v.size() > 1 ? std::sqrt(sq / static_cast<double>(v.size() - 1)) : 0.0};
  }
  return out;
}

}  // namespace skelgraph::depth_tracker
