#pragma once
// How good a skeleton stream is, measured as the thesis measured its Kinects
// against Vicon (section 5.1): per joint group, the detection rate is the share
// of frames in which its joints report confidence 1, and the error is the mean
// distance to ground truth over those joints only. Plus what needs no ground
// truth: how steady bone lengths are over time, and how often the whole upper
// body is present. DDS-free; `skelgraph eval`, the simulator's realism table
// and the tests use it.

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::eval {

inline constexpr std::size_t kGroupCount = 6;
const std::array<const char*, kGroupCount>& group_names();  // Head, Neck, Torso, Shoulders, Elbows, Hands
// Joint group of a canonical joint, or -1 (legs: the thesis measured the upper body only).
int group_of(skeleton::JointId j);

struct GroupFigures {
  double detection_pct = 0.0;  // share of joint-frames with confidence 1
  double error_cm = 0.0;       // mean distance to truth over those (NaN when none)
  std::uint64_t joint_frames = 0, tracked = 0;
};
using Figures = std::array<GroupFigures, kGroupCount>;

// Accumulates one stream's frames against truth.
class Accumulator {
 public:
  // A frame of the stream with the truth at its time (both in the same frame, metres).
  void add(const skeleton::Skeleton& estimate, const skeleton::Skeleton& truth);
  // Frames in which the stream reported nobody although the person was there.
  void add_missed(std::uint64_t frames = 1);
  Figures figures() const;
  // Mean error over every tracked upper-body joint (cm), NaN when none.
  double mean_error_cm() const;
  // Mean over the groups of their mean errors (cm): each group counts once, as in the thesis's tables.
  double mean_group_error_cm() const;

 private:
  std::array<double, kGroupCount> joint_frames_{}, tracked_{}, error_sum_{};
};

// Is the published uncertainty honest? For every tracked upper-body joint
// that carries a covariance: whether the truth lies inside its 95 % region
// (squared Mahalanobis distance within chi-square(3) 7.815), and how well
// its sigma (the root of the mean variance) ranks the actual error
// (Spearman; from up to 200 000 joint-ticks kept by reservoir sampling with
// a fixed seed, so memory stays bounded and runs repeat exactly).
class UncertaintyCheck {
 public:
  void add(const skeleton::Skeleton& estimate, const skeleton::Skeleton& truth);
  std::uint64_t joint_ticks() const { return n_; }
  double inside_95_pct() const;     // NaN when none
  double sigma_error_spearman() const;  // NaN with fewer than 3
  double median_sigma_cm() const;   // NaN when none
  // The reliability curve: for each nominal level (%), the joint-ticks whose
  // truth lies inside that level's region (%). Honest: on the diagonal.
  std::vector<std::pair<double, double>> reliability() const;

 private:
  static constexpr std::size_t kLevels = 11;
  std::uint64_t n_ = 0, inside_ = 0, rng_ = 0x9e3779b97f4a7c15ULL;
  std::array<std::uint64_t, kLevels> inside_level_{};
  std::vector<std::pair<double, double>> kept_;  // (sigma, error), m
};

// Spearman's rank correlation of paired values (ties get their mean rank); NaN with fewer than 3 or no spread.
double spearman(const std::vector<std::pair<double, double>>& xy);

// Ground truth of each person over time; linear interpolation between samples.
class TruthTimeline {
 public:
  void add(const skeleton::Skeleton& truth, std::int64_t t_ns);  // world frame
  // The truth person closest (torso) to `near` at t, if any sample brackets t
  // within max_gap_ns (or is that close to it).
  std::optional<skeleton::Skeleton> at(std::int64_t t_ns, const Eigen::Vector3d& near,
                                       std::int64_t max_gap_ns = 100'000'000) const;
  // Every person whose truth covers t (interpolated), in person-id order.
  std::vector<skeleton::Skeleton> all_at(std::int64_t t_ns, std::int64_t max_gap_ns = 100'000'000) const;
  std::size_t people() const { return by_person_.size(); }
  // True when some person's truth covers t.
  bool covers(std::int64_t t_ns, std::int64_t max_gap_ns = 100'000'000) const;
  // Drops the samples before t, keeping each person's last one before it (to interpolate from).
  void forget_before(std::int64_t t_ns);

 private:
  std::map<std::uint32_t, std::vector<std::pair<std::int64_t, skeleton::Skeleton>>> by_person_;
};

// Every joint of the evaluated groups (head to hands) at confidence 1.
bool upper_body_complete(const skeleton::Skeleton& s);

// Bone-length steadiness, no truth needed: for each upper-body bone, the
// standard deviation of its length over the frames where both ends have
// confidence 1, within each person (people's bones differ; the spread of
// each person's about their own mean is pooled); and the share of frames
// with every upper-body joint at confidence 1.
class Steadiness {
 public:
  void add(const skeleton::Skeleton& s);
  std::uint64_t frames() const { return frames_; }
  double upper_body_complete_pct() const;
  double mean_bone_sd_cm() const;  // mean over bones of each bone's length SD
  std::map<std::string, double> bone_sd_cm() const;

 private:
  struct Moments {
    double n = 0, sum = 0, sum2 = 0;
  };
  std::uint64_t frames_ = 0, complete_ = 0;
  std::map<std::pair<std::string, std::uint32_t>, Moments> bones_;  // by bone, person
};

}  // namespace skelgraph::eval
