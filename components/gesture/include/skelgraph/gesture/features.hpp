#pragma once
// Per-frame arm features for gesture recognition, the same offline and live.
//
// Thesis8 (the thesis's 8, so results compare): for the left then the right
// arm, the angle of the upper arm (shoulder -> elbow) and of the forearm
// (elbow -> hand) to the vertical, acos of the normalised dot product with
// (0, 1, 0), radians; then the four angular speeds |a(n) - a(n-1)| / dt over
// the real frame interval (rad/s; 0 on the first frame).
// Extended adds, per arm: the elbow bend (angle between upper arm and
// forearm) and the hand's height above the shoulder in upper-arm lengths.
//
// Missing joints: a frame where a joint an angle needs is below the minimum
// confidence keeps that angle's last good value (its speed is then 0) and is
// marked incomplete; frames before the first good value take the first good
// one (batch) or 0 until one comes (live). Frames whose stamps do not
// increase use the previous interval.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "skelgraph/gesture/hmm.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::gesture {

enum class FeatureSet { Thesis8, Extended };

struct FeatureOptions {
  FeatureSet set = FeatureSet::Thesis8;
  float min_confidence = skeleton::kTracked;
};

std::vector<std::string> feature_names(FeatureSet set);
std::optional<FeatureSet> feature_set_from_name(const std::string& name);  // "thesis8", "extended"

class FeatureStream {
 public:
  explicit FeatureStream(FeatureOptions options = {});
  // The features of the next frame (its stamp_ns gives the interval); `complete`: every joint was good.
  Eigen::VectorXd step(const skeleton::Skeleton& s, bool* complete = nullptr);
  void reset();
  int size() const;

 private:
  FeatureOptions o_;
  int angles_ = 0;
  Eigen::VectorXd last_good_;
  std::vector<bool> have_;
  std::int64_t last_ns_ = 0;
  double last_dt_ = 1.0 / 30;
  bool first_ = true;
};

struct Features {
  Sequence x;                  // T x size
  std::vector<bool> complete;  // per frame
};
// A clip's features; frames before the first good value of an angle take that first value.
Features features_of(const std::vector<skeleton::Skeleton>& frames, const FeatureOptions& options = {});

}  // namespace skelgraph::gesture
