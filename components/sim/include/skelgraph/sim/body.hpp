#pragma once
// The simulated person: segment lengths from body height and a pose, turned
// into the 15 canonical joints by forward kinematics. DDS-free; the scenarios
// drive BodyPose over time, the sensor and tracker models look at the result.
//
// World frame: metres, right-handed, y up, the floor at y = 0. A person with
// heading h faces (sin h, 0, cos h); their left is up x forward.

#include <Eigen/Core>

#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::sim {

// Segment lengths as fractions of body height (Drillis & Contini's standing
// proportions, as tabulated in Winter, "Biomechanics and Motor Control of
// Human Movement"), to the joint centres a skeleton tracker reports.
struct BodyDimensions {
  double height = 1.75;
  double hip_height = 0.530;       // hip joint centres above the floor (standing)
  double hip_width = 0.110;        // between the hip joint centres
  double trunk = 0.288;            // hip centre to the shoulder line (0.818 - 0.530)
  double neck_to_head = 0.118;     // shoulder line to the centre of the head (0.936 - 0.818)
  double shoulder_width = 0.259;   // between the shoulder joints
  double upper_arm = 0.186;
  double forearm_hand = 0.195;     // elbow to the centre of the hand (forearm 0.145 + half the hand)
  double thigh = 0.245;
  double shank = 0.246;            // knee to ankle (NITE's "foot" is at the ankle)
  double ankle_height = 0.039;

  // All lengths in metres for a person `height_m` tall; throws std::invalid_argument outside 0.5-2.5 m.
  static BodyDimensions from_height(double height_m);
};

struct ArmPose {
  double elevation = 0.0;   // rad: 0 hanging down, pi/2 horizontal, pi straight up
  double azimuth = 0.0;     // rad around the body's vertical: 0 forward, pi/2 out to the side, pi backwards
  double elbow_flex = 0.0;  // rad: 0 straight
  double bend_twist = 0.0;  // rad: turns the elbow's bending plane from forwards (0) towards the body's midline
};

struct LegPose {
  double hip_flex = 0.0;   // rad: thigh swung forward (negative: backward)
  double knee_flex = 0.0;  // rad: 0 straight
};

struct BodyPose {
  Eigen::Vector2d floor_position = Eigen::Vector2d::Zero();  // (x, z) of the hip centre over the floor
  double heading = 0.0;        // rad about +y; 0 faces +z
  double pelvis_drop = 0.0;    // m the hip centre is below standing height (sitting, crouching)
  double trunk_pitch = 0.0;    // rad forward bend at the hips
  ArmPose left_arm, right_arm;
  LegPose left_leg, right_leg;
};

// Joint positions and orientations (bone-aligned: local +y along the segment
// away from the body centre; trunk joints take the trunk's frame). Every joint
// has confidence 1: this is ground truth.
skeleton::Skeleton forward_kinematics(const BodyDimensions& body, const BodyPose& pose);

}  // namespace skelgraph::sim
