#pragma once
// Has a sensor been knocked out of place since it was calibrated?
//
// For every pair of sensors with poses, their skeletons are paired joint by
// joint in the world (under the poses; mirror-aware as in skeleton_calib)
// over a sliding window, and the pairs' offset (the median of a's joint minus
// b's, axis by axis) is taken. The first `settle_s` of a pair's shared views
// give its baseline: the trackers' own disagreement, which a calibrated cell
// keeps (a view of the back is placed a few centimetres off). A pair is off
// when its offset has moved from the baseline by `alarm_cm` (at the person:
// a sensor 2.5 m away turned by 3 degrees moves them 13 cm) for `confirm`
// evaluations in a row. A sensor has drifted when every pair it is in is off
// while some pair without it is within the alarm; with two sensors both are reported (two
// cannot tell which one moved). A sensor reported stays reported until it
// gets a new pose. A rigid fit over a few seconds of one person
// cannot tell a turn from a shift (its rotation wanders by degrees), so the
// offset at the person is what is watched and what the refined pose corrects.
//
// Time is passed in (the receive clock); no DDS. Skeletons are paired at
// their capture stamps mapped onto the receive clock (skeleton::StampMap,
// one per sensor): a sensor whose frames arrive in bursts, as they do from a
// busy host, is still paired with the others' poses of the same moment.

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "skelgraph/calib/skeleton_calib.hpp"
#include "skelgraph/skeleton/stamp_map.hpp"

namespace skelgraph::calib {

struct DriftOptions {
  double window_s = 10.0;          // each evaluation takes this much
  double settle_s = 20.0;          // the baseline: a pair's first this much of shared views
  double alarm_cm = 4.5;           // the offset at the person moved this much from the baseline
  double cell_m = 0.5;             // the baseline is kept per floor square of this size (where the joint is)
  int confirm = 3;                 // evaluations in a row
  std::size_t min_pairs = 300;     // joint pairs a window needs to be evaluated
  SkeletonCalibOptions pairing = wide_pairing();

  // Pairs within 30 cm (median 40 cm): a sensor turned by 3 degrees moves a
  // person 2-3 m away by 10-15 cm, which the calibration's 12 cm would cut
  // down.
  static SkeletonCalibOptions wide_pairing() {
    SkeletonCalibOptions o;
    o.inlier_threshold_m = 0.30;
    o.match_median_m = 0.40;
    return o;
  }
};

struct PairDrift {
  std::string a, b;
  bool has_baseline = false;
  bool evaluated = false;          // the last window had enough joint pairs
  std::size_t pairs = 0;           // ... how many
  Eigen::Vector3d change = Eigen::Vector3d::Zero();  // offset minus the baseline's (world, m)
  double shift_cm = 0;             // its length, cm
  int streak = 0;                  // evaluations in a row that were off
};

struct SensorDrift {
  std::string id;
  bool drifted = false;
  std::int64_t since_ns = 0;       // when it was first reported (drifted)
  double shift_cm = 0;             // against the pair that shows it best (most joint pairs)
  // The sensor's pose moved so that the person is where that pair's other
  // sensor sees them again (world_from_sensor; exact for a sensor moved,
  // right where the person was for a sensor turned).
  Eigen::Isometry3d refined = Eigen::Isometry3d::Identity();
};

class DriftMonitor {
 public:
  explicit DriftMonitor(DriftOptions options = {});

  // A sensor's calibrated pose (world_from_sensor); a new pose restarts the
  // baselines of its pairs.
  void set_pose(const std::string& sensor, const Eigen::Isometry3d& world_from_sensor);
  // A raw skeleton in the sensor's frame, received at receive_ns; its
  // stamp_ns (the capture, on the sensor's clock; 0: not given, the receive
  // time is taken) places it in time.
  void add(const std::string& sensor, std::int64_t receive_ns, const skeleton::Skeleton& s);
  // Evaluates the windows ending at now_ns (call about once a second).
  void update(std::int64_t now_ns);

  const std::vector<PairDrift>& pairs() const { return pairs_; }
  std::vector<SensorDrift> sensors() const;
  const DriftOptions& options() const { return o_; }

 private:
  struct PairState {
    std::int64_t start_ns = -1;    // first evaluation with enough views (baseline window start)
    // The baseline offset (a's joint minus b's, world) by where the joint
    // is: the trackers' disagreement depends on where the person stands.
    std::map<std::pair<int, int>, Eigen::Vector3d> baseline;
  };
  PairDrift& pair(const std::string& a, const std::string& b);
  std::vector<TimedSkeleton> window(const std::string& sensor, std::int64_t from_ns) const;

  DriftOptions o_;
  std::map<std::string, Eigen::Isometry3d> poses_;
  std::map<std::string, std::deque<TimedSkeleton>> data_;   // t_ns: the receive time
  std::map<std::string, skeleton::StampMap> clocks_;         // each sensor's stamps onto the receive clock
  std::vector<PairDrift> pairs_;
  std::vector<PairState> state_;   // parallel to pairs_
  std::map<std::string, std::int64_t> since_;  // sensor -> first reported
  std::int64_t now_ns_ = 0;
};

}  // namespace skelgraph::calib
