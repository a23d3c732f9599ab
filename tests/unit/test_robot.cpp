// The robot core: UR5e kinematics against its published zero pose, the
// Jacobian against finite differences, motion within the joint limits, the
// stopping model obeyed; capsule distances; the protective separation
// distance of ISO/TS 15066 and the decisions made on it, fail-safes included.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "skelgraph/eval/fetch.hpp"
#include "skelgraph/eval/safety.hpp"
#include "skelgraph/robot/arm.hpp"
#include "skelgraph/robot/command_gate.hpp"
#include "skelgraph/robot/capsule.hpp"
#include "skelgraph/robot/fetch.hpp"
#include "skelgraph/robot/follow.hpp"
#include "skelgraph/robot/separation.hpp"

using namespace skelgraph;
using namespace skelgraph::robot;
using Eigen::Vector3d;

TEST(RobotArm, Ur5eZeroPoseIsThePublishedOne) {
  const auto m = ArmModel::ur5e();
  const auto f = forward(m, Joints::Zero());
  // Flange at zero: x = a2 + a3, y = -(d4 + d6), z = d1 - d5.
  EXPECT_NEAR(f[6].translation().x(), -0.8172, 1e-9);
  EXPECT_NEAR(f[6].translation().y(), -0.2329, 1e-9);
  EXPECT_NEAR(f[6].translation().z(), 0.0628, 1e-9);
  // The tool point lies tool_length further along the flange's z.
  EXPECT_NEAR((f[7].translation() - f[6].translation()).norm(), m.tool_length, 1e-12);
}

TEST(RobotArm, JacobianMatchesFiniteDifferences) {
  const auto m = ArmModel::ur5e();
  Joints q;
  q << 0.3, -1.2, 1.4, -0.7, 1.1, 0.4;
  const auto j = position_jacobian(m, q);
  for (int i = 0; i < 6; ++i) {
    Joints dq = Joints::Zero();
    dq(i) = 1e-6;
    const Vector3d num = (forward(m, q + dq)[7].translation() - forward(m, q - dq)[7].translation()) / 2e-6;
    EXPECT_LT((num - j.col(i)).norm(), 1e-6) << "joint " << i;
  }
}

TEST(RobotArm, BasePoseStandsTheArmUpInTheYUpWorld) {
  const auto p = base_pose(1.0, 0.0, 2.0, 0.0);
  EXPECT_LT((p * Vector3d(0, 0, 0.5) - Vector3d(1.0, 0.5, 2.0)).norm(), 1e-12);  // base z is world up
  const auto m = ArmModel::ur5e();
  const auto caps = arm_capsules(m, Joints::Zero(), p);
  ASSERT_EQ(caps.size(), 7u);
  EXPECT_EQ(caps[0].name, "base");
  EXPECT_NEAR(caps[0].b.y(), 0.1625, 1e-9);  // the shoulder above the floor
}

TEST(RobotArm, ReachesATargetWithinItsLimits) {
  const auto m = ArmModel::ur5e();
  Joints start;
  start << 0.0, -1.57, 1.57, -1.57, -1.57, 0.0;
  ArmSim arm(m, base_pose(0, 0.8, 0, 0), start);
  const Vector3d target = arm.tool_world() + Vector3d(0.2, -0.1, 0.15);
  arm.set_target(target, 0.25);
  double max_tool = 0, max_joint = 0, max_accel = 0;
  Joints last = Joints::Zero();
  for (int k = 0; k < 500; ++k) {  // 5 s at 100 Hz
    arm.step(0.01);
    max_tool = std::max(max_tool, arm.tool_speed());
    max_joint = std::max(max_joint, arm.joint_speeds().cwiseAbs().maxCoeff());
    max_accel = std::max(max_accel, ((arm.joint_speeds() - last) / 0.01).cwiseAbs().maxCoeff());
    last = arm.joint_speeds();
  }
  EXPECT_LT((arm.tool_world() - target).norm(), 0.005);
  EXPECT_LT(max_tool, 0.25 * 1.02);
  EXPECT_LE(max_joint, m.max_speed.maxCoeff() + 1e-9);
  EXPECT_LE(max_accel, m.max_accel.maxCoeff() + 1e-6);
  // Half the speed scale: the tool goes half as fast.
  arm.set_speed_scale(0.5);
  arm.set_target(target + Vector3d(-0.3, 0, 0), 0.25);
  double top = 0;
  for (int k = 0; k < 300; ++k) {
    arm.step(0.01);
    top = std::max(top, arm.tool_speed());
  }
  EXPECT_LT(top, 0.125 * 1.02);
  EXPECT_GT(top, 0.1);
}

TEST(RobotArm, AProtectiveStopKeepsToTheStoppingModel) {
  const auto m = ArmModel::ur5e();
  Joints start;
  start << 0.0, -1.57, 1.57, -1.57, -1.57, 0.0;
  ArmSim arm(m, base_pose(0, 0.8, 0, 0), start);
  arm.set_target(arm.tool_world() + Vector3d(0.6, 0, 0), 0.5);
  for (int k = 0; k < 100; ++k) arm.step(0.005);
  const double v0 = arm.tool_speed();
  ASSERT_GT(v0, 0.3);
  const Vector3d from = arm.tool_world();
  arm.protective_stop();
  double t = 0, path = 0;
  Vector3d at = from;
  while (arm.tool_speed() > 0 && t < 2.0) {
    arm.step(0.005);
    t += 0.005;
    path += (arm.tool_world() - at).norm();
    at = arm.tool_world();
  }
  EXPECT_EQ(arm.tool_speed(), 0.0);
  EXPECT_LE(t, m.stopping.time_s(v0) + 0.01);
  EXPECT_LE(path, m.stopping.distance_m(v0) + 0.005);
  // Held until resumed.
  for (int k = 0; k < 50; ++k) arm.step(0.01);
  EXPECT_LT((arm.tool_world() - at).norm(), 1e-9);
  arm.resume();
  for (int k = 0; k < 50; ++k) arm.step(0.01);
  EXPECT_GT((arm.tool_world() - at).norm(), 0.05);
}

TEST(Capsules, DistancesOfSegmentsAndCapsules) {
  // Crossing at right angles, 1 m apart.
  EXPECT_NEAR(segment_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 1}, {0, 1, 1}), 1.0, 1e-12);
  // Parallel, overlapping in extent.
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {0.5, 0.3, 0}, {2, 0.3, 0}), 0.3, 1e-12);
  // End to end.
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}), 1.0, 1e-12);
  // Points.
  EXPECT_NEAR(segment_distance({0, 0, 0}, {0, 0, 0}, {0, 3, 4}, {0, 3, 4}), 5.0, 1e-12);
  const Capsule a{{0, 0, 0}, {1, 0, 0}, 0.1, "a"}, b{{0, 0.5, 0}, {1, 0.5, 0}, 0.15, "b"};
  EXPECT_NEAR(capsule_distance(a, b), 0.25, 1e-12);
  const auto c = closest({a, b}, {Capsule{{0.5, 2, 0}, {0.5, 3, 0}, 0.0, "far"}});
  EXPECT_EQ(c.first, 1u);
  EXPECT_NEAR(c.distance, 1.35, 1e-12);
}

TEST(Separation, ProtectiveDistanceFollowsTheFormula) {
  SeparationParams p;
  StoppingModel stop;  // 50 ms reaction, 2.5 m/s^2
  // v_r 0.5 m/s, T_r 0.1 s, Z_d 0.05 m, 1 m away: v_h 1.6.
  // T_s = 0.05 + 0.2 = 0.25; S_s = 0.025 + 0.05 = 0.075.
  // S_p = 1.6 (0.35) + 0.05 + 0.075 + 0 + 0.05 + 0.01 = 0.745
  EXPECT_NEAR(protective_distance(p, stop, 1.0, 0.5, 0.1, 0.05), 0.745, 1e-12);
  // Under 0.5 m the person is taken to move at 2.0 m/s.
  EXPECT_NEAR(protective_distance(p, stop, 0.4, 0.5, 0.1, 0.05), 0.745 + 0.4 * 0.35, 1e-12);
}

TEST(Separation, DecidesRunReducedOrStopAndFailsSafe) {
  SeparationParams p;
  StoppingModel stop;
  SeparationInput in;
  in.robot_max_speed = 1.0;
  in.robot_speed = 1.0;
  in.reaction_s = 0.1;
  in.person_uncertainty_m = 0.05;
  in.closest = "person 1 right_hand / tool";
  const double full = protective_distance(p, stop, 3.0, 1.0, 0.1, 0.05);
  in.separation_m = full + p.margin_m + 0.01;
  auto d = decide(p, stop, in);
  EXPECT_EQ(d.state, SafetyState::Run);
  EXPECT_EQ(d.speed_scale, 1.0);
  // Closer, the robot already slower: a reduced speed that fits (S_p at it plus the margin within the separation).
  in.robot_speed = 0.3;
  in.separation_m = full - 0.1;
  d = decide(p, stop, in);
  ASSERT_EQ(d.state, SafetyState::Reduced) << d.reason;
  EXPECT_GT(d.speed_scale, p.min_scale);
  EXPECT_LT(d.speed_scale, 1.0);
  EXPECT_NEAR(protective_distance(p, stop, in.separation_m, d.speed_scale, 0.1, 0.05) + p.margin_m, in.separation_m, 1e-6);
  // Within S_p at the speed it has: stop, naming the closest part.
  in.robot_speed = 1.0;
  d = decide(p, stop, in);
  EXPECT_EQ(d.state, SafetyState::ProtectiveStop);
  EXPECT_EQ(d.speed_scale, 0.0);
  EXPECT_NE(d.reason.find("person 1 right_hand / tool"), std::string::npos) << d.reason;
  // Nobody there: run.
  in.separation_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(decide(p, stop, in).state, SafetyState::Run);
  // Fail-safe: stale people data, stale robot state, a lost sensor, a person fusion cannot place;
  // and a person's stop gesture.
  for (int k = 0; k < 5; ++k) {
    SeparationInput bad = in;
    bad.separation_m = 10.0;  // far away: only the fail-safe stops it
    if (k == 0) bad.people_age_s = 0.3;
    if (k == 1) bad.robot_age_s = 0.2;
    if (k == 2) bad.coverage_lost = true;
    if (k == 3) bad.unplaced_person = true;
    if (k == 4) bad.stop_gesture = "stop gesture by person 2";
    const auto s2 = decide(p, stop, bad);
    EXPECT_EQ(s2.state, SafetyState::ProtectiveStop) << k;
    EXPECT_FALSE(s2.reason.empty());
    if (k == 4) {
      EXPECT_EQ(s2.reason, "stop gesture by person 2");
    }
  }
  SeparationInput fresh = in;
  fresh.separation_m = 10.0;
  EXPECT_EQ(decide(p, stop, fresh).state, SafetyState::Run);
}

TEST(Separation, PersonCapsulesComeFromTheReportedJointsWithTheirUncertainty) {
  skeleton::Skeleton s;
  for (auto& j : s.joints) j.confidence = skeleton::kTracked;
  s[skeleton::JointId::RightHand].position = Vector3d(0.5, 1.0, 0.2);
  s[skeleton::JointId::RightElbow].position = Vector3d(0.4, 1.1, 0.0);
  skeleton::set_covariance(s[skeleton::JointId::RightHand], Eigen::Matrix3d::Identity() * 0.0004);
  std::vector<std::vector<skeleton::JointId>> joints;
  auto caps = person_capsules(s, &joints);
  ASSERT_EQ(caps.size(), joints.size());
  EXPECT_EQ(caps.size(), 14u);  // 13 parts and the lower trunk
  std::size_t hand = 0;
  while (hand < caps.size() && caps[hand].name != "right_hand") ++hand;
  ASSERT_LT(hand, caps.size());
  EXPECT_EQ(joints[hand], (std::vector<skeleton::JointId>{skeleton::JointId::RightHand, skeleton::JointId::RightHand}));
  // The hand nearest a robot link beside it (+x): Z_d is the hand's 95 %
  // radius, the ellipsoid's largest axis (10 cm sigma in z).
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << 0.0004, 0.0004, 0.01;
  skeleton::set_covariance(s[skeleton::JointId::RightHand], cov);
  const Capsule link{{1.0, 0.5, 0.2}, {1.0, 1.5, 0.2}, 0.05, "forearm"};
  const auto sep = separation_to(s, {link});
  EXPECT_EQ(sep.part, "right_hand");
  EXPECT_EQ(sep.robot_part, "forearm");
  EXPECT_NEAR(sep.distance, 0.5 - 0.09 - 0.05, 1e-6);
  EXPECT_NEAR(sep.uncertainty_m, std::sqrt(7.815 * 0.01), 1e-4);
  EXPECT_TRUE(std::isinf(separation_to(s, {}).distance));
  // A joint not reported takes its parts away.
  s[skeleton::JointId::RightHand].confidence = 0;
  caps = person_capsules(s);
  EXPECT_EQ(caps.size(), 12u);  // no right forearm, no right hand
}

TEST(Separation, AStopIsReleasedOnlyAfterTheWayHasBeenClearForAWhile) {
  StopLatch latch(0.5);
  SafetyDecision run{SafetyState::Run, 1.0, 0.4, 0.6, "clear"};
  SafetyDecision stop{SafetyState::ProtectiveStop, 0.0, 0.5, 0.6, "close"};
  EXPECT_EQ(latch.apply(run, 0.0).state, SafetyState::Run);  // never stopped: no hold
  EXPECT_EQ(latch.apply(stop, 1.0).state, SafetyState::ProtectiveStop);
  auto held = latch.apply(run, 1.1);
  EXPECT_EQ(held.state, SafetyState::ProtectiveStop);
  EXPECT_EQ(held.speed_scale, 0.0);
  EXPECT_NE(held.reason.find("holding the stop"), std::string::npos);
  EXPECT_EQ(latch.apply(run, 1.5).state, SafetyState::ProtectiveStop);
  EXPECT_EQ(latch.apply(stop, 1.55).state, SafetyState::ProtectiveStop);  // a new stop starts the wait again
  EXPECT_EQ(latch.apply(run, 1.6).state, SafetyState::ProtectiveStop);
  EXPECT_EQ(latch.apply(run, 2.05).state, SafetyState::ProtectiveStop);
  EXPECT_EQ(latch.apply(run, 2.1).state, SafetyState::Run);  // clear for 0.5 s
  EXPECT_EQ(latch.apply(stop, 2.2).state, SafetyState::ProtectiveStop);  // stopping is never delayed
}

// Closed loop on the simulated robot cell, judged against the truth
// (eval/safety.hpp): a worker watched from four sides walks up to the arm,
// reaches in and walks past. The arm works, is stopped when the worker
// comes close, and is never allowed to move while the truth says it is too
// close for its speed.
namespace {
skelgraph::eval::SafetyRunOptions robot_cell(int repeats) {
  auto o = skelgraph::eval::robot_cell_options();
  o.sim.scenario.repeats = repeats;
  return o;
}
}  // namespace

TEST(SafetyRun, AWorkerWatchedFromFourSidesIsNeverTooCloseToAMovingArm) {
  const auto r = skelgraph::eval::run_safety(robot_cell(2));
  EXPECT_GT(r.seconds, 25.0);
  EXPECT_GT(r.task_points_reached, 0u);
  const auto moving = [&](const char* state) { return r.steps_by_state.count(state) ? r.steps_by_state.at(state) : 0u; };
  EXPECT_GT(moving("RUN") + moving("REDUCED"), 100u);  // the arm works
  EXPECT_GT(r.stops, 0u);
  EXPECT_GT(r.intrusions, 0u);  // the worker does come within S_p of the arm
  EXPECT_EQ(r.missed_steps, 0u);
  ASSERT_FALSE(r.reaction_ms.empty());
  // The reaction time is the data's age (the trackers' 50 ms in it) plus the command latency.
  EXPECT_GT(skelgraph::eval::quantile(r.reaction_ms, 0.5), 60.0);
  EXPECT_LT(r.min_true_separation_m, 0.5);
}

// Following a hand at the README's 1.2 m standoff: the arm is allowed to
// move, the tool never leaves the workspace once in it, it stays near where
// the true hand puts it while the hand is slow, and it lags by the trackers'
// delay and the arm's: more than 50 ms, well under a second.
TEST(SafetyRun, FollowingAHandStaysInTheWorkspaceAndLagsByTheDelays) {
  auto o = robot_cell(2);
  o.follow.emplace();
  o.follow->standoff_m = 1.2;
  const auto r = skelgraph::eval::run_safety(o);
  ASSERT_GT(r.follow_moving_steps, 50u);
  EXPECT_EQ(r.follow_outside_steps, 0u);
  ASSERT_EQ(r.follow_hand_speed.size(), r.follow_error_m.size());
  const auto slow = r.follow_error_at_most(0.5);
  ASSERT_GT(slow.size(), 20u);
  EXPECT_LT(skelgraph::eval::quantile(slow, 0.5), 0.3);
  EXPECT_GT(r.follow_lag_ms(), 50.0);
  EXPECT_LT(r.follow_lag_ms(), 1000.0);
}

// The lag is the delay of least mean distance; runs combine bin by bin; the
// slow-hand errors are those at or below the speed (an unknown speed is fast).
TEST(SafetyRun, TheFollowLagIsTheDelayOfLeastMeanDistance) {
  skelgraph::eval::SafetyRunResult r;
  r.decision_period_s = 0.01;
  r.follow_lag_sum_m = {3.0, 1.0, 2.0};  // means 0.3, 0.1, 0.5 m
  r.follow_lag_n = {10, 10, 4};
  EXPECT_DOUBLE_EQ(r.follow_lag_ms(), 10.0);
  r.follow_error_m = {0.1, 0.2, 0.3};
  r.follow_hand_speed = {0.2, 0.9, std::numeric_limits<double>::infinity()};
  EXPECT_EQ(r.follow_error_at_most(0.5), (std::vector<double>{0.1}));
  const auto all = skelgraph::eval::combine({r, r});
  EXPECT_EQ(all.follow_lag_n, (std::vector<std::uint64_t>{20, 20, 8}));
  EXPECT_DOUBLE_EQ(all.follow_lag_ms(), 10.0);
  EXPECT_EQ(all.follow_error_at_most(0.5), (std::vector<double>{0.1, 0.1}));
  EXPECT_EQ(skelgraph::eval::SafetyRunResult{}.follow_lag_ms(), 0.0);
}

// The judge can fail: a monitor whose commands take a second to act, with
// neither the position uncertainty nor the release hold, lets the arm move
// while the worker is too close, and its stops come late.
TEST(SafetyRun, TheJudgeCatchesASlowMonitor) {
  auto o = robot_cell(2);
  o.command_latency_s = 1.0;
  o.uncertainty_scale = 0.0;
  o.release_s = 0.0;
  const auto r = skelgraph::eval::run_safety(o);
  EXPECT_GT(r.missed_steps, 10u);
  EXPECT_GT(skelgraph::eval::quantile(r.time_to_stop_ms, 1.0), 100.0);
}


// A perfect tracker (the true people, late by the trackers' delay, no
// uncertainty) is never too close and stops the arm needlessly less often than
// the fused skeletons with their uncertainty do; its stops with the release
// hold taken away are only the latencies' (README: 1 % over the hour).
TEST(SafetyRun, APerfectTrackerSetsTheFloorOfNeedlessStops) {
  auto o = robot_cell(2);
  const auto fused = skelgraph::eval::run_safety(o);
  o.perfect_tracker = true;
  const auto perfect = skelgraph::eval::run_safety(o);
  EXPECT_EQ(perfect.missed_steps, 0u);
  EXPECT_GT(perfect.intrusions, 0u);
  EXPECT_LT(perfect.unnecessary_steps, fused.unnecessary_steps);
  ASSERT_FALSE(perfect.reaction_ms.empty());
  EXPECT_GT(skelgraph::eval::quantile(perfect.reaction_ms, 0.5), 60.0);  // the trackers' delay is kept
  o.release_s = 0.0;
  const auto no_hold = skelgraph::eval::run_safety(o);
  EXPECT_LT(no_hold.unnecessary_steps, perfect.unnecessary_steps);
  EXPECT_LT(no_hold.share_pct(no_hold.unnecessary_steps), 5.0);
}
// Every sensor falls silent from 8 s on: the monitor stops the arm (the
// people data grows old, the sensors are lost) and keeps it stopped.
TEST(SafetyRun, EverySensorSilentStopsTheArm) {
  auto o = robot_cell(2);
  o.trace_period_s = 0.1;
  for (const auto& s : o.sim.sensors) o.dropouts.push_back({s.id, 8.0, 0.0, 1000.0});
  const auto r = skelgraph::eval::run_safety(o);
  // Too close only while the last data grew old (max_people_age_s, 25 steps), if at all.
  EXPECT_LE(r.missed_steps, 25u);
  std::size_t after = 0, stopped = 0;
  for (const auto& p : r.trace) {
    if (p.t < 8.6) continue;  // 0.25 s for the data to grow old, the command latency, a tick
    ++after;
    stopped += p.state == SafetyState::ProtectiveStop;
  }
  EXPECT_GT(after, 100u);
  EXPECT_EQ(stopped, after);
}

TEST(SafetyRun, QuantilesAndBadConfigurations) {
  EXPECT_EQ(skelgraph::eval::quantile({}, 0.5), 0.0);
  EXPECT_EQ(skelgraph::eval::quantile({3, 1, 2, 4}, 0.5), 2.0);
  EXPECT_EQ(skelgraph::eval::quantile({3, 1, 2, 4}, 1.0), 4.0);
  auto o = robot_cell(1);
  o.task.clear();
  EXPECT_THROW(skelgraph::eval::run_safety(o), std::invalid_argument);
}

TEST(SafetyRun, RunsCombineAndDropoutsParse) {
  skelgraph::eval::SafetyRunResult a, b;
  a.seconds = 60;
  a.steps = 100;
  a.stop_steps = 25;
  a.steps_by_state = {{"RUN", 75}, {"PROTECTIVE_STOP", 25}};
  a.time_to_stop_ms = {120, 80};
  a.min_true_separation_m = 0.9;
  b.seconds = 30;
  b.steps = 300;
  b.missed_steps = 2;
  b.steps_by_state = {{"RUN", 300}};
  b.time_to_stop_ms = {200};
  b.min_true_separation_m = 0.4;
  const auto all = skelgraph::eval::combine({a, b});
  EXPECT_EQ(all.seconds, 90);
  EXPECT_EQ(all.steps, 400u);
  EXPECT_EQ(all.missed_steps, 2u);
  EXPECT_EQ(all.steps_by_state.at("RUN"), 375u);
  EXPECT_EQ(all.time_to_stop_ms, (std::vector<double>{120, 80, 200}));
  EXPECT_EQ(all.min_true_separation_m, 0.4);
  EXPECT_EQ(all.share_pct(all.stop_steps), 6.25);
  EXPECT_EQ(skelgraph::eval::SafetyRunResult{}.share_pct(0), 0.0);
  EXPECT_TRUE(std::isinf(skelgraph::eval::combine({}).min_true_separation_m));

  const std::vector<std::string> sensors{"sensor1", "sensor2"};
  const auto d = skelgraph::eval::parse_dropout("sensor2,20,5", sensors);
  EXPECT_EQ(d.sensor, "sensor2");
  EXPECT_EQ(d.from_s, 15.0);
  EXPECT_TRUE(d.silent(16.0));
  EXPECT_FALSE(d.silent(21.0));
  EXPECT_TRUE(d.silent(36.0));
  const auto error = [&](const std::string& spec) {
    try {
      skelgraph::eval::parse_dropout(spec, sensors);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(error("sensor1,20").find("expected SENSOR,EVERY_S,FOR_S"), std::string::npos);
  EXPECT_NE(error("sensor1,20,5,1").find("expected SENSOR,EVERY_S,FOR_S"), std::string::npos);
  EXPECT_NE(error("sensor9,20,5").find("no sensor 'sensor9'"), std::string::npos);
  EXPECT_NE(error("sensor1,x,5").find("must be numbers"), std::string::npos);
  EXPECT_NE(error("sensor1,5,20").find("0 < FOR_S < EVERY_S"), std::string::npos);
}

// Following a hand: the tool keeps the standoff on the robot's side of the
// hand, inside the workspace; it holds without a tracked hand or with old
// data; it stays with the person it follows while they are there.
TEST(Follow, TheToolKeepsItsStandoffFromTheHandAndHoldsWithoutOne) {
  FollowParams p;
  p.standoff_m = 0.5;
  p.workspace = Eigen::AlignedBox3d(Vector3d(-1, 0, 0), Vector3d(1, 2, 3));
  Follower f(p, Vector3d(0, 0, 2));  // the base 2 m ahead of the origin
  const auto person = [](std::uint32_t id, const Vector3d& hand, std::int64_t captured) {
    skeleton::Skeleton s;
    s.person_id = id;
    for (auto& j : s.joints) j.confidence = skeleton::kTracked;
    s[skeleton::JointId::RightHand].position = hand;
    s.capture_newest_ns = captured;
    return s;
  };
  const std::int64_t now = 1'000'000'000;
  auto t = f.step({person(4, Vector3d(0, 1.2, 0.5), now - 60'000'000)}, now);
  ASSERT_FALSE(t.hold) << t.reason;
  EXPECT_EQ(t.person, 4u);
  EXPECT_TRUE(t.target.isApprox(Vector3d(0, 1.2, 1.0), 1e-9));  // 0.5 m towards the base, at the hand's height
  // Another person nearer the workspace does not take over while person 4 is there.
  t = f.step({person(4, Vector3d(0.3, 1.2, 0.5), now - 60'000'000), person(5, Vector3d(0, 1.2, 1.5), now)}, now);
  EXPECT_EQ(t.person, 4u);
  // Clamped into the workspace.
  t = f.step({person(4, Vector3d(0.3, 2.5, 0.5), now)}, now);
  EXPECT_NEAR(t.target.y(), 2.0, 1e-9);
  // Holds: data too old, hand not tracked, nobody.
  EXPECT_TRUE(f.step({person(4, Vector3d(0, 1.2, 0.5), now - 400'000'000)}, now).hold);
  auto untracked = person(4, Vector3d(0, 1.2, 0.5), now);
  untracked[skeleton::JointId::RightHand].confidence = skeleton::kInferred;
  EXPECT_TRUE(f.step({untracked}, now).hold);
  EXPECT_TRUE(f.step({}, now).hold);
  // Person 4 gone: the one with a hand nearest the workspace.
  t = f.step({person(5, Vector3d(0, 1.2, 0.5), now)}, now);
  EXPECT_EQ(t.person, 5u);
}

// Pointing to fetch: the tool hovers 15 cm above a pointed spot the robot
// reaches, and goes nowhere for one out of reach or under its own base.
TEST(Fetch, TheToolHoversAboveAReachableSpotOnly) {
  const Vector3d base(0, 0, 1.9);
  const auto t = fetch_target(Vector3d(0.3, 0, 1.4), base);
  ASSERT_TRUE(t.has_value());
  EXPECT_TRUE(t->isApprox(Vector3d(0.3, 0.15, 1.4), 1e-12));
  EXPECT_FALSE(fetch_target(Vector3d(0, 0, 0.5), base).has_value());  // 1.4 m away
  EXPECT_FALSE(fetch_target(Vector3d(0.1, 0, 1.9), base).has_value());  // the robot's own footprint
}

// On simulated pointing sessions the chain (spotting, the spotted target,
// the arm moving to hover) ends most fetches near the true spot; the counts
// are consistent.
TEST(Fetch, SpottedPointingSendsTheArmNearTheTrueSpot) {
  skelgraph::eval::FetchRunOptions o;
  o.sessions = 4;
  o.world_from_base = base_pose(0.5, 0.0, 1.2, 180.0);
  const auto r = skelgraph::eval::run_fetch(o);
  EXPECT_EQ(r.pointing, 24);  // six in each session
  EXPECT_GT(r.in_reach, 3);
  EXPECT_LE(r.spotted, r.in_reach);
  EXPECT_LE(r.fetched, r.spotted);
  EXPECT_EQ(static_cast<int>(r.error_m.size()), r.fetched);
  EXPECT_GT(r.within, r.fetched / 2);
}

// The robot's own check of a command beside the permissions (issue 39).
TEST(RobotCommandGate, KnownSourcesAndFreshStampsOnly) {
  using skelgraph::robot::CommandGate;
  using skelgraph::robot::check_command;
  const CommandGate gate{{"separation", "operator"}, 1.0};
  const std::int64_t now = 1'000'000'000'000;
  EXPECT_TRUE(check_command(gate, "separation", now - 200'000'000, now).ok);
  EXPECT_TRUE(check_command(gate, "operator", now + 500'000'000, now).ok);  // a sender's clock a little ahead
  const auto stranger = check_command(gate, "mallory", now, now);
  EXPECT_FALSE(stranger.ok);
  EXPECT_FALSE(stranger.stale);
  EXPECT_NE(stranger.reason.find("'mallory'"), std::string::npos);
  const auto old = check_command(gate, "separation", now - 1'500'000'000, now);
  EXPECT_FALSE(old.ok);
  EXPECT_TRUE(old.stale);
  EXPECT_NE(old.reason.find("1.500 s ago"), std::string::npos) << old.reason;
  EXPECT_FALSE(check_command(gate, "separation", now + 2'000'000'000, now).ok);  // from the future
  EXPECT_FALSE(check_command(gate, "separation", 0, now).ok);                    // no stamp
  EXPECT_TRUE(check_command(CommandGate{{}, 1.0}, "anyone", now, now).ok);       // no list: any source
}
