#pragma once
// A statistical model of a depth-camera skeleton tracker (the Kinect SDK or
// NITE) watching one person through one virtual sensor: when it finds and
// loses the person, which joints it claims to track (confidence 1 / 0.5 / 0),
// and how wrong its positions are. The reasoning behind each effect is in the
// component README; the numbers are in the two profiles. DDS-free.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "skelgraph/sim/rng.hpp"
#include "skelgraph/sim/scenario.hpp"
#include "skelgraph/sim/sensor.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::sim {

struct TrackerProfile {
  std::string name;
  // Finding and losing the person.
  double acquire_s = 0.3;          // the body must be in sight this long before the first skeleton
  double reacquire_s = 0.5;        // ... and this long after a loss
  double lose_fraction = 0.35;     // lost when fewer of the joints than this are in sight
  double ghost_s = 0.2;            // after that, keeps reporting the last skeleton (confidence 1) this long,
                                   // sliding onto a nearby prop (a wall-sized blob looks like a person)
  double ghost_on_prop_s = 0.2;     // ... or this long once it has latched onto a prop
  double settle_sd = 0.15, settle_s = 0.7;  // a fresh skeleton starts this wrong (m) and settles in this time
  // Confidence.
  bool out_of_view_lost = false;        // joints outside the image: 0 (else 0.5)
  double self_hidden_tracked = 0.0;     // share of time a joint hidden behind the body still claims 1
  double object_hidden_tracked = 0.0;   // ... hidden behind a wall or a box
  double near_object_inferred = 0.0;    // share of time a joint touching an object drops to 0.5
  double back_limbs_inferred = 0.0;     // share of time arm joints drop to 0.5 with the back to the sensor
  double back_shoulders_factor = 1.0;   // ... times this for the shoulders (NITE keeps them: 360, 100 %)
  double head_doubt = 0.0;              // share of time the head is 0.5 standing upright
  double head_doubt_unusual = 0.0;      // ... added when bent over or sitting
  double elbow_doubt_bent = 0.0;        // share of time elbows are 0.5 when bent over
  double elbow_doubt_sitting = 0.0;     // ... when sitting
  double doubt_dwell_s = 0.5;           // how long a drop to 0.5 lasts on average
  // Left/right flips with the back to the sensor (degrees of view angle, hysteresis).
  double flip_on_deg = 115.0, flip_off_deg = 70.0;
  double flip_delay_s = 0.4, unflip_delay_s = 0.4;  // mean time to flip, to recover
  // Accuracy.
  std::array<Eigen::Vector3d, skeleton::kJointCount> offset{};  // constant, body frame (right, up, forward), m
  double bias_sd = 0.02, bias_tau_s = 0.8;   // temporally correlated error per joint, m / s
  double hand_bias_sd = 0.035;
  double back_bias_gain = 1.5;               // bias grows by this factor with the back to the sensor
  double noise_sd = 0.006;                   // white noise at 2 m, grows with depth squared
  double lag_s = 0.03;                       // smoothing lag: fast joints trail
  double hidden_sd = 0.08;                   // error of a joint reported while hidden
  double contamination = 0.5;                // pull towards an object partly hiding the body

  static const TrackerProfile& by_name(const std::string& name);  // "mssdk" or "nite"; throws
  static const std::vector<std::string>& names();
};

// Per-joint visibility from one sensor.
struct Visibility {
  std::array<bool, skeleton::kJointCount> in_view{};
  std::array<bool, skeleton::kJointCount> object_hidden{};  // behind a prop or another person
  std::array<bool, skeleton::kJointCount> self_hidden{};    // behind the person's own trunk or head
  std::array<bool, skeleton::kJointCount> near_object{};    // within a few cm of a prop
  std::array<double, skeleton::kJointCount> hit_depth{};    // where the line of sight meets the prop (m)
  double sighted_fraction = 0.0;  // in view and not hidden by props or people
  double object_fraction = 0.0;   // share of the upper body (head to hands) hidden by props or people
  double prop_fraction = 0.0;     // ... by props alone (what drags the fitted skeleton towards a prop)
};

Visibility visibility(const SensorView& view, const Scene& scene, std::size_t actor,
                      const std::vector<skeleton::Skeleton>& truths, double body_scale);

class TrackerModel {
 public:
  // `next_user_id` is shared by the models of one sensor: each (re)acquired
  // person gets a new user id, as NITE and the Kinect SDK do.
  // `body_scale`: the person's height over 1.75 m (sizes the body's volume for occlusion).
  TrackerModel(const TrackerProfile& profile, const SensorConfig& sensor, Rng rng, double noise_scale,
               double body_scale, std::uint32_t* next_user_id);

  // One frame at world time t: the skeleton in the sensor frame, or nothing
  // when the tracker has no user for this person. `actor` out of range: the
  // person is not in the scene (left the cell).
  std::optional<skeleton::Skeleton> observe(double t, const Scene& scene, std::size_t actor,
                                            const std::vector<skeleton::Skeleton>& truths);

  bool flipped() const { return flipped_; }
  // The sensor now stands elsewhere (it was bumped): what follows is seen from there.
  void move_sensor(const SensorConfig& sensor) { view_ = SensorView(sensor); }

 private:
  enum class State { Searching, Tracking, Ghost };
  void evolve_errors(double dt, double back);
  std::optional<skeleton::Skeleton> ghost(double dt, const Scene& scene);
  std::optional<skeleton::Skeleton> observe_nobody(double t, double dt, const Scene& scene);
  struct Flicker {
    bool on = false;
    void step(double p, double dwell, double dt, Rng& rng);
  };

  const TrackerProfile& p_;
  SensorView view_;
  Rng rng_;
  double noise_scale_;
  double body_scale_;
  std::uint32_t* next_user_id_;
  std::uint32_t user_id_ = 0;
  State state_ = State::Searching;
  bool acquired_once_ = false;
  double sighted_since_ = -1.0;
  double lost_at_ = 0.0;
  double last_t_ = -1.0;
  bool flipped_ = false;
  std::array<Eigen::Vector3d, skeleton::kJointCount> bias_{}, hidden_bias_{}, last_truth_{};
  std::array<Flicker, skeleton::kJointCount> doubt_{}, hidden_claim_{}, near_drop_{};
  std::optional<skeleton::Skeleton> last_report_;
  std::array<Eigen::Vector3d, skeleton::kJointCount> report_world_{}, settle_{};
  double acquired_at_ = 0.0;
  bool ghost_on_prop_ = false;
  std::uint64_t frame_ = 0;
};

}  // namespace skelgraph::sim
