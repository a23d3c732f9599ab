#pragma once
// Live gesture spotting for one person: finds gestures in a continuous
// skeleton stream without being told where they start, classifies them with
// a trained Classifier, and for pointing gives the ray and where it meets a
// surface (the floor by default). Eigen/std only, time from the skeletons'
// stamps: the same core runs offline on recordings and inside the `gesture`
// component.
//
// Motion state, from the hands (speed of the smoothed hand over a short
// window, height):
//   resting  both hands low (below the shoulders by more than `rest_drop`
//            of the arm's length, within `rest_reach` of them horizontally)
//            and still;
//   holding  still, but a hand is not at rest (e.g. the arm held out);
//   moving   otherwise.
// A segment opens when the person leaves resting (with `pad` of the frames
// before) and closes after `settle` s of resting again. Pointing fires early:
// once an extended arm (shoulder -> hand at least `extended` of the arm's
// length) has been held still for `hold` s, the segment so far is classified;
// if the point class wins and is not rejected, the event goes out when the
// arm moves again or `aim` s after the hold began, whichever is first, with
// the shoulder -> hand ray averaged over the hold (the trackers' errors
// wander over about a second, so a longer look halves the target error of a
// quarter-second one). A held class (`held_labels`: "stop") that wins then
// goes out at once, without a ray. Any other segment is classified when it
// closes; an event goes out when its class is not garbage (or, for a
// classifier without a garbage class, not below the rejection threshold),
// and for pointing only when an extended arm was held in the segment.

#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/skeleton/skeleton.hpp"
#include "skelgraph/skeleton/stats.hpp"

namespace skelgraph::gesture {

enum class MotionState { Resting, Moving, Holding };

const char* motion_state_name(MotionState s);

// A plane the pointing ray may hit: points p with normal . (p - point) = 0.
struct Surface {
  std::string name = "floor";
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
};

// "name:x,y,z" (a horizontal plane through the point) or "name:x,y,z:nx,ny,nz".
// Throws std::invalid_argument naming the text.
Surface parse_surface(const std::string& text);

// Where the ray origin + s * direction (s > 0) meets the surface; nullopt when it never does.
std::optional<Eigen::Vector3d> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Surface& s);

struct SpotterOptions {
  double still_speed = 0.25;   // m/s: a hand slower than this is still...
  double window = 0.25;        // s: ...measured over this long
  double smoothing = 0.08;     // s: time constant of the hand-position filter
  double rest_drop = 0.55;     // a hand at rest is this many arm lengths below its shoulder...
  double rest_reach = 0.35;    // ...and within this many arm lengths of it horizontally
  double settle = 0.20;        // s of resting that closes a segment
  double pad = 0.17;           // s of frames before the segment opened that go with it
  double hold = 0.25;          // s an extended arm must be held before pointing is tried
  double aim = 1.5;            // s of the hold the ray is averaged over, at most (<= hold: the event at once)
  double warmup = 1.0;         // s after a person's first skeleton before a hold counts (a fresh track is still settling)...
  double lost = 0.3;           // ...and after a gap of more than this many s in the person's skeletons (lost and found again)
  double extended = 0.80;      // shoulder -> hand share of the arm's length that counts as extended...
  double min_raise = 35.0;     // ...with the shoulder -> hand line at least this many degrees from hanging straight down
  double min_length = 0.4;     // s: shorter segments are ignored
  double max_length = 10.0;    // s: longer ones are cut (classified and reopened)
  // Pointing, told from work that holds an arm out (docs/experiments/2026-12-04-quiet-gestures.md):
  double max_target = 0.0;     // m: the ray must meet a surface within this of the shoulder (0: any ray, none needed;
                               // a cell whose surfaces are known uses 4: sim_spotter_options(), the `gesture` component)
  bool other_arm_free = true;  // the other arm not held out as well (carrying, a stretch, hands on the knees)
  double min_confidence = 0.0; // events less sure than this are dropped (the operating point: recall against false alarms)
  double confirm = 0.0;        // s: pointing must stay held this long after `hold` or it is dropped (a confirmation; 0: none)
  // Pointing's posture, averaged over the hold (docs/experiments/2026-12-05-pointing-posture.md):
  double min_straightness = 0.90; // shoulder -> hand over the arm's length, at least (1: straight; 0: any). Real
                                  // adults point with the elbow a little bent: 0.93 lost one of Kinder-Gator's ten
  double max_lean_m = 0.0;        // the neck off the torso horizontally, at most, m (0: any). Needs a level world
                                  // frame: the simulated cell and the `gesture` component use 0.07; a recording's
                                  // camera may be tilted, so `gesture spot` leaves it off
  std::string point_label = "point";
  // Other gestures made by holding an arm out (a raised palm: "stop"): fired
  // early too, once held `hold` s, without a ray; the rest when their segment closes.
  std::vector<std::string> held_labels{"stop"};
  std::vector<Surface> surfaces{Surface{}};  // the ray's target: the nearest hit
};

struct SpottedEvent {
  std::string label;
  std::uint32_t person_id = 0;
  std::int64_t start_ns = 0, end_ns = 0;  // the segment (end: the frame it was decided on)
  double log_likelihood = 0.0;            // per frame, of the winning class
  double confidence = 0.0;                // 1 - exp(-margin): 0 a tie with the next class, near 1 clear
  bool has_ray = false;                   // pointing: the ray below is valid
  Eigen::Vector3d ray_origin = Eigen::Vector3d::Zero(), ray_direction = Eigen::Vector3d::Zero();
  bool has_target = false;                // the ray meets a surface
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  std::string target_name;
  std::string arm;                        // "left" / "right" for pointing
  Eigen::Vector3d out = Eigen::Vector3d::Zero();  // horizontal, away from the body on the pointing arm's side
  // Pointing: how the body held the ray, averaged over it.
  double straightness = 0.0;  // shoulder -> hand over the arm's length (1: the arm straight)
  double lean_m = std::numeric_limits<double>::quiet_NaN();  // the neck off the torso horizontally, m
};

// One arm's body axes (PointingCorrection's joint offsets are in them), from
// the shoulders' left -> right direction (horizontal).
struct ArmFrame {
  ArmFrame(const Eigen::Vector3d& across, bool right);
  Eigen::Vector3d out, up, forward;
  Eigen::Vector3d to_world(const Eigen::Vector3d& body) const { return body.x() * out + body.y() * up + body.z() * forward; }
  Eigen::Vector3d to_body(const Eigen::Vector3d& w) const { return {w.dot(out), w.dot(up), w.dot(forward)}; }
};

// The ray turned by a correction (see PointingCorrection); `out` as in SpottedEvent.
Eigen::Vector3d corrected(const Eigen::Vector3d& direction, const Eigen::Vector3d& out, const PointingCorrection& c);
// The angles a ray is off a true one: elevation (degrees, up positive) and azimuth (degrees, outwards positive).
PointingCorrection ray_offset(const Eigen::Vector3d& direction, const Eigen::Vector3d& truth, const Eigen::Vector3d& out);

class Spotter {
 public:
  Spotter(const Classifier& classifier, SpotterOptions options = {});
  // The next skeleton of this person (stamps increasing); the events decided on it.
  // `wrists`: required by models on the `hands` features (recorded Kinect
  // data, offline: the skeleton topics carry no wrists), a ModelError without.
  std::vector<SpottedEvent> step(const skeleton::Skeleton& s, const Wrists* wrists = nullptr);
  MotionState state() const { return state_; }
  bool in_segment() const { return open_; }
  const SpotterOptions& options() const { return o_; }

 private:
  struct Frame {
    std::int64_t t;
    Eigen::VectorXd x;
  };
  std::vector<SpottedEvent> close(std::int64_t now_ns, bool final);
  std::optional<SpottedEvent> decide(std::int64_t now_ns, bool early);
  struct RaySample {
    std::int64_t t;
    Eigen::Vector3d origin, direction;
    bool both = false;  // the other arm was held out too
    double straight = 1.0;  // shoulder -> hand over the arm's length (1: straight)
    double lean_m = std::numeric_limits<double>::quiet_NaN();  // the neck off the torso horizontally (NaN: not tracked)
  };
  using Rays = std::vector<RaySample>;
  void aim(SpottedEvent& e, const Rays& rays, int side) const;  // the ray and its target
  // The gathered pointing event, aimed; nullopt when the whole hold no longer looks like pointing.
  std::optional<SpottedEvent> release_aiming(const Rays& rays, std::int64_t end_ns);
  bool pointing_posture(const SpottedEvent& e) const;  // straight arm, upright trunk (min_straightness, max_lean_m)

  const Classifier& c_;
  SpotterOptions o_;
  FeatureStream features_;
  std::deque<Frame> before_;      // the last `pad` s before a segment
  std::vector<Frame> segment_;
  bool open_ = false, fired_ = false;
  std::int64_t last_ns_ = 0, rest_since_ = -1, hold_since_[2] = {-1, -1};
  double speed_[2] = {0, 0};
  Eigen::Vector3d last_hand_[2];  // smoothed
  std::deque<std::pair<std::int64_t, Eigen::Vector3d>> trail_[2];
  bool have_last_ = false;
  std::int64_t first_ns_ = -1;  // the person's first skeleton, or the first after a gap
  MotionState state_ = MotionState::Resting;
  // Ray samples of the current hold per arm (origin, direction).
  Rays rays_[2];
  Rays best_rays_;  // the segment's longest hold
  int best_side_ = -1;
  std::optional<SpottedEvent> aiming_;  // pointing decided, its ray still gathered over the hold
  int aiming_side_ = -1;
  std::int64_t aiming_hold_ns_ = 0;  // when the hold being aimed began
  bool have_hand_[2] = {false, false};
  std::uint32_t person_ = 0;
  Eigen::Vector3d across_ = Eigen::Vector3d::UnitX();  // left -> right shoulder, horizontal
};

// --- Evaluation on continuous streams ---

struct TruthGesture {
  std::string label;
  std::int64_t start_ns = 0, end_ns = 0;
  std::int64_t hold_ns = -1;        // pointing: when the hold began (-1: unknown)
  bool has_target = false;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  bool has_ray = false;  // pointing: the true ray (mean over the hold)
  Eigen::Vector3d ray_origin = Eigen::Vector3d::Zero(), ray_direction = Eigen::Vector3d::Zero();
};

struct SpottingReport {
  std::string label;
  int truth = 0, events = 0, true_positive = 0, false_positive = 0, false_negative = 0;
  double precision = 0, recall = 0, f1 = 0;
  std::vector<double> latency_s;        // event minus gesture end, per matched event (negative: before the end)
  std::vector<double> latency_hold_s;   // event minus the start of the hold (pointing)
  std::vector<double> target_error_m;   // matched events with both targets
  std::vector<double> ray_error_deg;    // matched events with both rays: angle between the directions
  double median_latency_s = 0, median_latency_hold_s = 0, median_target_error_m = 0, max_target_error_m = 0;
  double median_ray_error_deg = 0;
  // False alarms per hour of the stream outside the label's true gestures
  // (non_gesture_s: set by whoever made the stream; 0: not known, then NaN).
  double non_gesture_s = 0, false_per_hour = 0;
};

// Matches events of `label` to truth gestures of that label: an event within
// [start - slack, end + slack] of an unmatched truth gesture is a true
// positive; the rest are false positives; unmatched truth gestures are misses.
SpottingReport score_spotting(const std::vector<SpottedEvent>& events, const std::vector<TruthGesture>& truth,
                              const std::string& label, double slack_s = 0.5);
// Several streams' reports as one (counts summed, per-event figures pooled).
SpottingReport combine(const std::vector<SpottingReport>& parts);
// Fills precision, recall, F1 and the medians from the counts and lists.
void finish(SpottingReport& r);
nlohmann::json to_json(const SpottingReport& r);

}  // namespace skelgraph::gesture
