#pragma once
// Speed-and-separation monitoring after ISO/TS 15066 (5.5.4), DDS-free. NOT a
// certified safety function: it follows the standard's formula so the gap to
// a certified one is plain (sensing, software and stop categories are not).
//
// Protective separation distance:
//   S_p = S_h + S_r + S_s + C + Z_d + Z_r
//   S_h = v_h (T_r + T_s)  the person walking towards the robot while the
//                          system reacts and the robot stops
//   S_r = v_r T_r          the robot moving on while the system reacts
//   S_s                    the robot's stopping distance from v_r
//   C                      intrusion distance (0 here: the body is modelled
//                          by capsules, reach included)
//   Z_d, Z_r               position uncertainty of the person (the fused
//                          joints' 95 % radius) and of the robot
// v_h is ISO 13855's 1.6 m/s, 2.0 m/s when the separation is under 0.5 m;
// T_r is measured: the age of the people data plus compute and command latency.

#include <string>
#include <vector>

#include "skelgraph/robot/arm.hpp"
#include "skelgraph/robot/capsule.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::robot {

struct SeparationParams {
  double human_speed = 1.6, human_speed_near = 2.0, near_m = 0.5;  // ISO 13855
  double intrusion_m = 0.0;           // C
  double robot_uncertainty_m = 0.01;  // Z_r
  double margin_m = 0.3;              // full speed only with this much room beyond S_p
  double min_scale = 0.1;             // below this a reduced speed is no use: stop
  double max_people_age_s = 0.25;     // older people data: stop
  double max_robot_age_s = 0.1;       // older robot state: stop
};

enum class SafetyState { Run, Reduced, ProtectiveStop };
const char* safety_state_name(SafetyState s);  // "RUN", "REDUCED", "PROTECTIVE_STOP"

// S_p for a robot tool speed v_r (m/s), reaction time T_r (s), person
// uncertainty Z_d (m) and the separation d (m) now (which human speed applies).
double protective_distance(const SeparationParams& p, const StoppingModel& stop, double separation_m, double v_r,
                           double reaction_s, double person_uncertainty_m);

// A person's body as capsules, from the joints it reports (confidence > 0):
// head, trunk, upper arms, forearms, hands, thighs, shins. Each capsule's
// name is its body part ("right_forearm", ...); `joints` gets, per capsule,
// the joints it is made from.
std::vector<Capsule> person_capsules(const skeleton::Skeleton& s,
                                     std::vector<std::vector<skeleton::JointId>>* joints = nullptr);

// A person's part closest to the robot's capsules: the surface distance
// (+inf: no parts or no robot), Z_d there and the two parts' names. Z_d is
// the larger 95 % radius of the part's joints (skeleton::radius_95: the
// largest axis of the 95 % ellipsoid; 0 without covariance). (The 95 % bound
// along the line to the robot alone, 1.96 sigma, was tried: needless stops
// 39 -> 29 %, but 13 steps in an hour where the arm moved too close.)
struct PersonSeparation {
  double distance = 0;
  double uncertainty_m = 0;
  std::string part, robot_part;
};
PersonSeparation separation_to(const skeleton::Skeleton& person, const std::vector<Capsule>& robot);

struct SeparationInput {
  double separation_m = 0;         // closest person capsule to robot capsule, surface to surface (+inf: nobody)
  double person_uncertainty_m = 0; // Z_d at the closest part
  std::string closest;             // "person 3 right_hand / forearm"
  double robot_speed = 0;          // tool speed now, m/s
  double robot_max_speed = 1.0;    // the speed asked of it, m/s
  double reaction_s = 0.1;         // T_r, measured
  double people_age_s = 0;         // how old the people data is (+inf: none yet)
  double robot_age_s = 0;          // how old the robot state is (+inf: none yet)
  bool coverage_lost = false;      // a sensor covering the robot's surroundings is lost and none other covers it
  bool unplaced_person = false;    // fusion reports a person it cannot place
  std::string stop_gesture;        // a person asked for a stop by gesture: who and when ("" none)
};

struct SafetyDecision {
  SafetyState state = SafetyState::ProtectiveStop;
  double speed_scale = 0;        // what the robot is commanded
  double protective_m = 0;       // S_p at the robot's speed now
  double protective_full_m = 0;  // S_p at the speed asked
  std::string reason;
};

SafetyDecision decide(const SeparationParams& p, const StoppingModel& stop, const SeparationInput& in);

// After a protective stop, the robot stays stopped until the decisions have
// allowed it to move for `release_s` without a break: a worker walking along
// the boundary does not start and stop it over and over. Stopping is never
// delayed. Time passed in.
class StopLatch {
 public:
  explicit StopLatch(double release_s) : release_s_(release_s) {}
  SafetyDecision apply(SafetyDecision d, double now_s);

 private:
  double release_s_;
  bool stopped_ = false;
  double clear_since_s_ = 0;
  bool clear_ = false;
};

}  // namespace skelgraph::robot
