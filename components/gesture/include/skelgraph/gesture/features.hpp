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
// Body: the hand and the elbow relative to the shoulder in the body's frame
// (out to that arm's side, up, forward: forward is horizontal, square to the
// shoulder line, so it does not depend on where the sensor is), in arm
// lengths (upper arm + forearm of that frame); each knee's height relative to
// its hip in leg lengths (hip -> knee -> foot; walking in place lifts it);
// then the signed velocities of the hand coordinates and the knee heights
// (per second). Order: hands, knees, elbows, speeds. Left and right are mirror
// images: out is away from the body on both sides.
//
// Hands (Kinect v1/v2 recordings, offline: the skeleton topics carry no
// wrist): per arm (left, then right) the thesis's two angles and the
// forearm's direction along the body's outward axis (horizontal, along the
// shoulders; -1 across the body .. 1 out to the side: a wave swings it); then
// per arm the hand segment (wrist -> hand): its angle to the vertical (a
// raised palm turns it up) and its length in forearm lengths (elbow -> wrist;
// a pointing finger makes it longer); then the speeds of the first six.
// Signal-to-stop and push-a-button hold the arm forward like pointing; the
// hand tells them apart.
// Arm (Kinect v1/v2 recordings, offline, like hands): per arm the thesis's two
// angles and forearm_out, as in hands; then per arm the hand segment's
// forward reach (hand - wrist along the body's forward axis, in arm lengths:
// a pointing finger stretches towards the target, a pushing fist or flat
// palm does not) and its sway (the standard deviation, over the last 0.5 s,
// of the hand segment's direction along the outward axis: a hand waved from
// the wrist swings it, a raised one does not); then the speeds of the first
// six. Models see only the active arm: clips are made right-handed and the
// left arm's columns dropped (model_view), so the way a subject holds the
// other arm does not count.
//
// Missing joints: a frame where a joint an angle needs is below the minimum
// confidence keeps that angle's last good value (its speed is then 0) and is
// marked incomplete; frames before the first good value take the first good
// one (batch) or 0 until one comes (live). Frames whose stamps do not
// increase use the previous interval; intervals shorter than min_interval
// count as min_interval.

#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "skelgraph/gesture/hmm.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::gesture {

enum class FeatureSet { Thesis8, Extended, Body, Hands, Arm };

struct FeatureOptions {
  FeatureSet set = FeatureSet::Thesis8;
  float min_confidence = skeleton::kTracked;
  double min_interval = 0.02;  // s: speeds are taken over at least this long (frames 1 ms apart would make noise huge)
};

std::vector<std::string> feature_names(FeatureSet set);
// Joints beyond the canonical 15 that `hands` uses; NaN: not reported.
struct Wrists {
  Eigen::Vector3d left = Eigen::Vector3d::Constant(std::nan("")), right = Eigen::Vector3d::Constant(std::nan(""));
};
bool needs_wrists(FeatureSet set);  // without them its wrist values are missing in every frame
// Sets whose models see one arm only: the right one of a right-handed clip.
bool one_arm(FeatureSet set);
// The columns of a (right-handed) clip a model of `set` sees: without the left arm's for one_arm sets, else all.
std::vector<Eigen::Index> model_columns(FeatureSet set);
Sequence model_view(const Sequence& x, FeatureSet set);
std::optional<FeatureSet> feature_set_from_name(const std::string& name);  // "thesis8", "extended", "body", "hands", "arm"
const char* feature_set_name(FeatureSet set);
// Column i of a mirrored sequence is column perm[i] of the original: left and right swapped.
std::vector<int> mirror_permutation(FeatureSet set);
Sequence mirrored(const Sequence& x, FeatureSet set);
// The clip as performed by its more active arm on the right: mirrored when the
// left arm's values vary more over the clip (sum of variances). `was` (if set)
// tells whether it mirrored.
Sequence right_handed(const Sequence& x, FeatureSet set, bool* was = nullptr);

// The part of a clip where the arms move: frames whose values (not speeds)
// are further than `share` of the clip's largest excursion from both the rest
// pose at the start and the one at the end (each the mean of the first/last
// `rest_frames`), padded by `pad` frames. [begin, end); the whole clip when
// nothing moves.
struct Span {
  Eigen::Index begin = 0, end = 0;
};
Span motion_span(const Sequence& x, FeatureSet set, double share = 0.2, int rest_frames = 5, int pad = 5);

class FeatureStream {
 public:
  explicit FeatureStream(FeatureOptions options = {});
  // The features of the next frame (its stamp_ns gives the interval); `complete`: every joint was good.
  // `raw`: the frame's own values (NaN where missing), before holding.
  Eigen::VectorXd step(const skeleton::Skeleton& s, bool* complete = nullptr, Eigen::VectorXd* raw = nullptr,
                       const Wrists* wrists = nullptr);
  void reset();
  int size() const;
  int values() const { return values_; }  // the first values() features; the rest are speeds

 private:
  FeatureOptions o_;
  int values_ = 0, speeds_ = 0;
  bool signed_speed_ = false;
  std::vector<std::pair<int, int>> arm_;  // angle sets: (side, value kind) of each value
  Eigen::VectorXd last_good_;
  std::vector<bool> have_;
  std::int64_t last_ns_ = 0;
  double last_dt_ = 1.0 / 30;
  bool first_ = true;
  std::vector<std::pair<int, std::deque<std::pair<std::int64_t, double>>>> sway_;  // arm: each sway column's recent values
};

struct Features {
  Sequence x;                  // T x size
  std::vector<bool> complete;  // per frame
};
// A clip's features; frames before the first good value of an angle take that first value.
// `wrists` (one per frame) for the sets that use them.
Features features_of(const std::vector<skeleton::Skeleton>& frames, const FeatureOptions& options = {},
                     const std::vector<Wrists>* wrists = nullptr);

}  // namespace skelgraph::gesture
