#pragma once
// One skeleton per person from many unsynchronised sensors. DDS-free: raw
// skeletons go in with the time they arrived (the caller's clock), fused
// skeletons come out in the world frame at whatever times the caller asks
// (sync ticks, or a fixed rate). The `fusion` component and `skelgraph fuse`
// drive the same core, so live and offline results agree.
//
// Methods (per joint, over the sensors that currently see the person):
//  avg      the thesis's: one sensor with confidence 1 -> take it; several ->
//           their mean. No sensor at 1 -> the same over confidence 0.5.
//  sum      the thesis's: among sensors with confidence 1 for the joint, the
//           one whose skeleton has the highest confidence sum.
//  facing   the sensor the torso faces (the thesis's first demo), else any.
//  weighted mean weighted by confidence, view angle and distance; sensors
//           seeing the person's back corrected as kalman's are.
//  kalman   a constant-velocity filter per joint; measurement noise from
//           confidence, view angle and distance; Mahalanobis gating; sensors
//           seeing the person's back (left/right swapped) are detected against
//           the person's heading and corrected (with sensors on opposite
//           sides, the heading is a belief fed by what tells front from back:
//           a forward lean, the front view's surer arms); limb lengths held steady;
//           when two sensors place the person apart, the one whose skeleton
//           lies in front of the other's along its own line of sight (it sees
//           an occluder, where a tracker that lost the person leaves its
//           ghost) is left out.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::fusion {

enum class Method { Avg, Sum, Facing, Weighted, Kalman };
const std::vector<std::string>& method_names();  // "avg", "sum", "facing", "weighted", "kalman"
std::optional<Method> method_from_name(std::string_view name);
const char* method_name(Method m);

struct FuserOptions {
  Method method = Method::Kalman;
  std::int64_t max_age_ns = 100'000'000;          // older samples are not used at a fusion time
  std::int64_t delay_ns = 0;                       // fuse this far in the past (room to interpolate)
  bool interpolate = true;                         // between the samples around the fusion time, when both exist
  std::int64_t sensor_timeout_ns = 1'000'000'000;  // silent this long: the sensor is dropped (degraded)
  std::int64_t person_timeout_ns = 1'000'000'000;  // no input this long: the fused person is forgotten
  double match_distance_m = 0.6;                   // a sensor's skeleton joins a fused person this close (torso)
  // kalman: each joint predicted this far past the fusion time (its velocity
  // and covariance carried forward): the trackers' own delay plus the
  // consumer's, so the skeleton says where the person is when it is used.
  std::int64_t predict_ns = 0;
  // Every sensor's tracker delay unless set_capture_latency says otherwise.
  std::int64_t capture_latency_ns = 0;
  // The sensors stamp on the caller's clock (one host, or clocks kept in step
  // by PTP): capture times are their stamps. Otherwise (the default) each
  // sensor's clock is brought onto the caller's by its quickest delivery,
  // which also takes any constant delay between its stamp and its delivery
  // (a tracker's processing) for clock offset: only the varying part of that
  // delay shows in the age.
  bool shared_clock = false;
  // kalman and weighted: the trackers' joint-placement error that averaging
  // cannot remove, added to each joint's published covariance (fuser.cpp,
  // kBiasSdM: fitted on the simulator's NITE model), times this scale; 0
  // publishes the filter's and the sensors' part alone.
  double bias_sd_scale = 1.0;
};

struct FuserStats {
  std::uint64_t added = 0, no_pose = 0, fused = 0, flips_corrected = 0, gated = 0;
  std::uint64_t tracks_merged = 0;  // a sensor's stream moved to an older track of the same person
  std::uint64_t streams_ended = 0;  // remove(): a sensor's tracker said it lost a person
  std::uint64_t headings_reversed = 0;  // a heading the views' evidence held against, turned round
  // kalman: views left out because they disagreed with another sensor's and
  // lay in front of it along their own line of sight (on an occluder: a ghost)
  std::uint64_t occluded_views = 0;
  // kalman: views of a frozen stream (the same skeleton shape frame after
  // frame: a tracker's ghost of a person it lost) left out because no person
  // was within 0.3 m of them
  std::uint64_t ghost_views = 0;
};

class Fuser {
 public:
  explicit Fuser(FuserOptions options);
  ~Fuser();
  Fuser(Fuser&&) noexcept;
  Fuser& operator=(Fuser&&) noexcept;

  // Where a sensor is: p_world = world_from_sensor * p_sensor. Samples of a
  // sensor without a pose are counted and ignored.
  void set_pose(const std::string& sensor, const Eigen::Isometry3d& world_from_sensor);
  bool has_pose(const std::string& sensor) const;
  // The sensor's tracker delay: its skeletons show the body this long before
  // their stamps (NITE about 50 ms). Only the capture stamps use it.
  void set_capture_latency(const std::string& sensor, std::int64_t ns);

  // The sensor delivered a frame at t_ns (whether or not it saw anyone): it is alive.
  void heartbeat(const std::string& sensor, std::int64_t t_ns);

  // A raw skeleton in its sensor's frame, received at t_ns.
  void add(const skeleton::Skeleton& raw, std::int64_t t_ns);

  // The sensor's tracker lost this person (its DDS instance was disposed):
  // the stream ends now. A fused person left with no stream is gone at the
  // next fuse(), without waiting for person_timeout_ns.
  void remove(const std::string& sensor, std::uint32_t person_id);

  // Fused person ids forgotten by fuse() since the last call (every sensor
  // lost them, or none reported them for person_timeout_ns): they left.
  std::vector<std::uint32_t> take_departed();

  // The fused skeleton of every person seen at t_ns (minus delay): world
  // frame, sensor_id "fused", stable person ids, joint sensor_mask bit i =
  // sensors()[i] contributed, capture_oldest/newest_ns when the sensors'
  // skeletons it was made from were captured, on the caller's clock: each
  // sensor's stamps shifted by the least (arrival - stamp) seen lately (its
  // clock need not be ours), minus its capture latency; an interpolated
  // view's stamp interpolated alike. Call with non-decreasing times.
  std::vector<skeleton::Skeleton> fuse(std::int64_t t_ns);

  // Every sensor seen so far, in mask-bit order.
  std::vector<std::string> sensors() const;
  // Sensors that sent data before but none within the timeout at t_ns.
  std::vector<std::string> silent_sensors(std::int64_t t_ns) const;
  const FuserStats& stats() const;
  const FuserOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skelgraph::fusion
