#pragma once
// Checking a tracker on depth images without ground truth (`skelgraph depth
// track`): per image, whether each reported joint lies on what the image shows
// (on_surface); over the images, how much the nearest person's bone lengths
// spread (a body does not change its bones between frames). Eigen/std only.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "skelgraph/depth/depth_image.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::depth_tracker {

struct JointOnImage {
  skeleton::JointId joint{};
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double confidence = 0.0;
  bool on_person = false;
};

struct PersonOnImage {
  std::uint32_t person_id = 0;
  bool nearest = false;  // the person the image is of (the smallest torso depth); the others are whatever else it holds
  std::vector<JointOnImage> joints;  // the reported joints (confidence above 0), in joint order
  std::size_t on_person = 0;         // of them, on the person
};

// Every tracked person of an image, in the tracker's order; a joint more than
// on_person_m in front of the surface at its pixel is off the person.
std::vector<PersonOnImage> check_people(const depth::DepthImage& image, const std::vector<skeleton::Skeleton>& people,
                                        double on_person_m = 0.05);

struct BoneSpread {
  std::size_t images = 0;
  double mean_m = 0.0, sd_m = 0.0;  // sample standard deviation (0 for one image)
};

// The lengths of six upper-body bones (neck-head, the shoulders, both upper
// and lower arms), each where both ends are reported, gathered over images.
class BoneSpreads {
 public:
  void add(const skeleton::Skeleton& s);
  // By "joint-joint" name (neck-head), for the bones seen at least once.
  std::map<std::string, BoneSpread> summary() const;

 private:
  std::map<std::string, std::vector<double>> lengths_;
};

}  // namespace skelgraph::depth_tracker
