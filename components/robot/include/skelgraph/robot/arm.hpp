#pragma once
// A 6-axis industrial arm, DDS-free: kinematics from Denavit-Hartenberg
// parameters, a capsule model of its links, motion of the tool towards a
// target under joint speed and acceleration limits, and a stopping model.
// The robot's base frame is the DH one (z up); world_from_base places it in
// the cell (world: y up), see base_pose().

#include <array>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "skelgraph/robot/capsule.hpp"

namespace skelgraph::robot {

using Joints = Eigen::Matrix<double, 6, 1>;

struct DhJoint {
  double a = 0, d = 0, alpha = 0;  // standard DH: m, m, rad (theta is the joint variable)
};

// How far and how long the arm takes to stop from a tool speed v (m/s), as a
// robot's data sheet gives it: a reaction before braking, then constant
// deceleration. Stopping distance S_s = v t_react + v^2 / (2 decel); time
// T_s = t_react + v / decel.
struct StoppingModel {
  double reaction_s = 0.05;
  double decel_m_s2 = 2.5;
  double distance_m(double v) const { return v * reaction_s + v * v / (2.0 * decel_m_s2); }
  double time_s(double v) const { return reaction_s + v / decel_m_s2; }
};

struct ArmModel {
  std::string name;
  std::array<DhJoint, 6> dh{};
  Joints max_speed = Joints::Constant(3.14159);  // rad/s
  Joints max_accel = Joints::Constant(8.0);      // rad/s^2
  Joints lower = Joints::Constant(-6.283), upper = Joints::Constant(6.283);  // rad
  double max_tool_speed = 1.0;                   // m/s
  double tool_length = 0.10;                     // m, from the flange along its z
  // Capsule radius per segment: base, upper arm, forearm, wrist 1, wrist 2, wrist 3, tool.
  std::array<double, 7> radius{};
  StoppingModel stopping;

  // Universal Robots UR5e: DH parameters from Universal Robots, "Parameters
  // for calculations of kinematics and dynamics" (FAQ 45257); joint speeds
  // 180 deg/s and tool speed 1 m/s from its data sheet; capsule radii and
  // the stopping model are ours (envelopes of the link housings; a
  // conservative stop), not the manufacturer's figures.
  static ArmModel ur5e();
};

// Frames of the base (0), each joint after its rotation (1..6) and the tool
// point (7), in the base frame.
std::array<Eigen::Isometry3d, 8> forward(const ArmModel& m, const Joints& q);
// The tool point's position Jacobian (3x6, base frame).
Eigen::Matrix<double, 3, 6> position_jacobian(const ArmModel& m, const Joints& q);
// The arm's capsules (base, links, tool) in the world.
std::vector<Capsule> arm_capsules(const ArmModel& m, const Joints& q, const Eigen::Isometry3d& world_from_base);
// The DH base frame (z up) standing on the floor of the y-up world at
// (x, y, z), turned yaw_deg about the vertical.
Eigen::Isometry3d base_pose(double x, double y, double z, double yaw_deg);

// The arm moving: the tool towards a target (world) at up to a speed, scaled
// by a speed scale (1 full speed, 0 stands still), within the joint speed and
// acceleration limits; a protective stop brakes along the stopping model and
// holds until resume. Time is passed in (step's dt).
class ArmSim {
 public:
  ArmSim(ArmModel model, Eigen::Isometry3d world_from_base, Joints start);

  void set_target(const Eigen::Vector3d& tool_world, double max_speed_m_s);
  void clear_target();  // hold where it is
  void set_speed_scale(double s);  // clamped to [0, 1]
  void protective_stop();
  void resume();

  void step(double dt_s);

  const ArmModel& model() const { return m_; }
  const Eigen::Isometry3d& world_from_base() const { return world_from_base_; }
  const Joints& joints() const { return q_; }
  const Joints& joint_speeds() const { return qd_; }
  Eigen::Vector3d tool_world() const;
  double tool_speed() const;  // m/s, in the world
  double speed_scale() const { return scale_; }
  bool stopped() const { return stop_; }
  bool has_target() const { return has_target_; }
  std::vector<Capsule> capsules() const { return arm_capsules(m_, q_, world_from_base_); }

 private:
  ArmModel m_;
  Eigen::Isometry3d world_from_base_;
  Joints q_, qd_ = Joints::Zero();
  Eigen::Vector3d target_ = Eigen::Vector3d::Zero();
  double target_speed_ = 0.25, scale_ = 1.0;
  bool has_target_ = false, stop_ = false;
  double stop_elapsed_ = 0.0, stop_from_speed_ = 0.0;
  Eigen::Vector3d stop_direction_ = Eigen::Vector3d::Zero();
};

}  // namespace skelgraph::robot
