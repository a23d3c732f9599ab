// The open depth tracker on rendered depth images: it finds the person, fits
// the body model close to the truth, stays on one id, says when it cannot tell
// sides, ignores walls, and forgets people who leave.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "skelgraph/depth_tracker/frame_matcher.hpp"
#include "skelgraph/depth_tracker/image_check.hpp"
#include "skelgraph/depth_tracker/sim_depth.hpp"
#include "skelgraph/depth_tracker/tracker.hpp"
#include "skelgraph/sim/body.hpp"
#include "skelgraph/sim/depth_render.hpp"

using namespace skelgraph;
using skeleton::JointId;

namespace {
sim::SensorConfig sensor_at(const Eigen::Vector3d& position, double yaw_deg) {
  sim::SensorConfig c;
  c.id = "s";
  c.position = position;
  c.yaw = yaw_deg * M_PI / 180.0;
  return c;
}
// A standing person at the origin facing heading_deg (0: +z), right arm held out forward.
skeleton::Skeleton person(double heading_deg, double x = 0.0) {
  sim::BodyPose pose;
  pose.floor_position = Eigen::Vector2d(x, 0.0);
  pose.heading = heading_deg * M_PI / 180.0;
  pose.right_arm = sim::arm_forward();
  return sim::forward_kinematics(sim::BodyDimensions::from_height(1.75), pose);
}
// A sensor, its renderer, and a tracker that knows the sensor's pose.
struct Rig {
  explicit Rig(sim::SensorConfig c) : cfg(std::move(c)), r(cfg, depth::kinect_intrinsics(320, 240)) {
    tracker.set_pose(cfg.world_from_sensor());
  }
  sim::SensorConfig cfg;
  sim::DepthRenderer r;
  depth_tracker::DepthTracker tracker;
};
depth::DepthImage shot(const sim::DepthRenderer& r, const std::vector<skeleton::Skeleton>& people, sim::Rng& rng,
                       std::int64_t t_ns) {
  auto img = r.render(people, {}, rng, 1.75, 1.1);
  img.stamp_ns = t_ns;
  return img;
}
}  // namespace

TEST(DepthTracker, FitsAPersonFacingTheSensorWithinAFewCentimetres) {
  const auto cfg = sensor_at({0.0, 1.2, 2.5}, 180.0);  // 2.5 m in front, looking at them
  sim::DepthRenderer r(cfg, depth::kinect_intrinsics(320, 240));
  depth_tracker::DepthTracker tracker;
  tracker.set_pose(cfg.world_from_sensor());
  sim::Rng rng(5);
  const auto truth = person(0.0);
  std::vector<skeleton::Skeleton> out;
  for (int k = 0; k < 10; ++k) out = tracker.track(shot(r, {truth}, rng, k * 33'000'000));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].sensor_id, "s");
  EXPECT_EQ(out[0].stamp_ns, 9 * 33'000'000);
  double sum = 0;
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    const auto id = skeleton::joint_at(j);
    if (id == JointId::LeftFoot || id == JointId::RightFoot) continue;  // at the floor, partly cut with it
    const Eigen::Vector3d world = cfg.world_from_sensor() * out[0].joints[j].position;
    const double err = (world - truth[id].position).norm();
    EXPECT_LT(err, 0.08) << skeleton::joint_name(id);
    sum += err;
  }
  EXPECT_LT(sum / 13.0, 0.04);
  // Facing the sensor, the upper body is seen and vouched for.
  for (auto j : {JointId::Head, JointId::Neck, JointId::Torso, JointId::LeftShoulder, JointId::RightShoulder,
                 JointId::RightElbow, JointId::RightHand}) {
    EXPECT_EQ(out[0][j].confidence, skeleton::kTracked) << skeleton::joint_name(j);
  }
  // The right hand (held forward) is on the right: left and right were not swapped.
  const Eigen::Vector3d hand = cfg.world_from_sensor() * out[0][JointId::RightHand].position;
  EXPECT_LT((hand - truth[JointId::RightHand].position).norm(), 0.08);
  EXPECT_EQ(tracker.stats().initialisations, 1u);
}

TEST(DepthTracker, SeenSideOnItDoesNotVouchForLeftAndRight) {
  const auto cfg = sensor_at({2.5, 1.2, 0.0}, -90.0);  // on +x, looking along -x at the person's left side
  sim::DepthRenderer r(cfg, depth::kinect_intrinsics(320, 240));
  depth_tracker::DepthTracker tracker;
  tracker.set_pose(cfg.world_from_sensor());
  sim::Rng rng(6);
  sim::BodyPose pose;  // arms hanging
  const auto truth = sim::forward_kinematics(sim::BodyDimensions::from_height(1.75), pose);
  std::vector<skeleton::Skeleton> out;
  for (int k = 0; k < 10; ++k) out = tracker.track(shot(r, {truth}, rng, k * 33'000'000));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_GT(out[0][JointId::Head].confidence, 0.0f);
  for (auto j : {JointId::LeftShoulder, JointId::RightShoulder, JointId::LeftHand, JointId::RightHand}) {
    EXPECT_EQ(out[0][j].confidence, skeleton::kLost) << skeleton::joint_name(j);
  }
  const Eigen::Vector3d head = cfg.world_from_sensor() * out[0][JointId::Head].position;
  EXPECT_LT((head - truth[JointId::Head].position).norm(), 0.06);
}

TEST(DepthTracker, AnEmptyRoomHasNobodyAndPeopleWhoLeaveAreForgotten) {
  Rig rig(sensor_at({0.0, 1.2, 2.5}, 180.0));
  sim::Rng rng(7);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(rig.tracker.track(shot(rig.r, {}, rng, k * 33'000'000)).empty());  // walls, floor
  std::uint32_t first_id = 0;
  for (int k = 5; k < 15; ++k) {
    const auto out = rig.tracker.track(shot(rig.r, {person(0.0)}, rng, k * 33'000'000));
    ASSERT_EQ(out.size(), 1u) << k;
    if (first_id == 0) first_id = out[0].person_id;
    EXPECT_EQ(out[0].person_id, first_id);  // one id while tracked
  }
  // Gone for a second (longer than lost_after_s), then back: a new person.
  for (int k = 15; k < 45; ++k) EXPECT_TRUE(rig.tracker.track(shot(rig.r, {}, rng, k * 33'000'000)).empty());
  const auto back = rig.tracker.track(shot(rig.r, {person(0.0)}, rng, 45 * 33'000'000));
  ASSERT_EQ(back.size(), 1u);
  EXPECT_NE(back[0].person_id, first_id);
}

TEST(DepthTracker, TwoPeopleAreTwoSkeletons) {
  Rig rig(sensor_at({0.0, 1.2, 3.0}, 180.0));
  sim::Rng rng(8);
  std::vector<skeleton::Skeleton> out;
  for (int k = 0; k < 5; ++k) out = rig.tracker.track(shot(rig.r, {person(0.0, -0.7), person(0.0, 0.7)}, rng, k * 33'000'000));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NE(out[0].person_id, out[1].person_id);
  const double x0 = (rig.cfg.world_from_sensor() * out[0][JointId::Torso].position).x();
  const double x1 = (rig.cfg.world_from_sensor() * out[1][JointId::Torso].position).x();
  EXPECT_NEAR(std::abs(x0 - x1), 1.4, 0.1);
}

TEST(DepthTracker, MergedViewsFitOneModelToEverySensorsPoints) {
  const auto front = sensor_at({0.0, 1.2, 2.5}, 180.0), side = sensor_at({2.5, 1.2, 0.0}, -90.0);
  sim::DepthRenderer rf(front, depth::kinect_intrinsics(320, 240)), rs(side, depth::kinect_intrinsics(320, 240));
  depth_tracker::DepthTracker merged, single;
  single.set_pose(side.world_from_sensor());
  sim::Rng rng(9);
  const auto truth = person(0.0);
  std::vector<skeleton::Skeleton> out, side_only;
  for (int k = 0; k < 10; ++k) {
    auto a = shot(rf, {truth}, rng, k * 33'000'000), b = shot(rs, {truth}, rng, k * 33'000'000);
    side_only = single.track(b);
    out = merged.track_merged({a, b}, {front.world_from_sensor(), side.world_from_sensor()});
  }
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].sensor_id, "merged");
  EXPECT_EQ(out[0].frame_id, "world");
  double sum = 0;
  for (auto j : {JointId::Head, JointId::Neck, JointId::Torso, JointId::LeftShoulder, JointId::RightShoulder,
                 JointId::LeftElbow, JointId::RightElbow, JointId::LeftHand, JointId::RightHand}) {
    const double err = (out[0][j].position - truth[j].position).norm();
    EXPECT_LT(err, 0.06) << skeleton::joint_name(j);
    EXPECT_GT(out[0][j].confidence, 0.0f) << skeleton::joint_name(j);  // the front view tells the sides
    sum += err;
  }
  EXPECT_LT(sum / 9.0, 0.035);
  EXPECT_EQ(out[0][JointId::LeftShoulder].confidence, skeleton::kTracked);
  EXPECT_EQ(out[0][JointId::RightShoulder].confidence, skeleton::kTracked);
  // The side sensor alone cannot vouch for the arms.
  ASSERT_EQ(side_only.size(), 1u);
  EXPECT_EQ(side_only[0][JointId::RightHand].confidence, skeleton::kLost);
  EXPECT_THROW(merged.track_merged({}, {}), std::invalid_argument);
}

TEST(DepthTracker, BadInputIsRefused) {
  depth_tracker::TrackerOptions bad;
  bad.voxel_m = 0.0;
  EXPECT_THROW(depth_tracker::DepthTracker{bad}, std::invalid_argument);
  depth_tracker::DepthTracker tracker;
  auto img = depth::DepthImage::blank(depth::kinect_intrinsics(32, 24));
  img.mm.resize(10);
  EXPECT_THROW(tracker.track(img), std::invalid_argument);
}

TEST(DepthTracker, OnTheSimulatedPointScenarioOneSensorStaysUnderTenCentimetres) {
  sim::SimConfig cfg;
  cfg.scenario.name = "point";
  cfg.sensors = sim::default_sensors(1);
  depth_tracker::SimDepthOptions o;
  o.intrinsics = depth::kinect_intrinsics(160, 120);  // small, to keep the test quick
  o.girth = 1.2;
  const auto r = depth_tracker::track_simulated_depth(cfg, o);
  ASSERT_GT(r.frames, 100u);
  std::map<std::string, Eigen::Isometry3d> poses{{cfg.sensors[0].id, cfg.sensors[0].world_from_sensor()}};
  eval::OfflineOptions eo;
  eo.methods = {};
  const auto scored = eval::evaluate(poses, r.events, eo);
  ASSERT_EQ(scored.streams.size(), 1u);
  const auto& s = scored.streams[0];
  EXPECT_GT(s.with_output, s.ticks * 9 / 10);
  EXPECT_LT(s.accuracy.mean_error_cm(), 10.0);
}

TEST(DepthTracker, JointLimitsCheckFoldedElbowsAndBackwardKnees) {
  auto s = person(0.0);
  EXPECT_FALSE(depth_tracker::check_joint_limits(s).any());
  // Fold the right forearm back onto the upper arm: 10 degrees at the elbow.
  const Eigen::Vector3d sh = s[JointId::RightShoulder].position, el = s[JointId::RightElbow].position;
  const Eigen::Vector3d upper = (sh - el).normalized();
  const Eigen::Vector3d side = upper.cross(Eigen::Vector3d::UnitX()).normalized();
  s[JointId::RightHand].position = el + 0.25 * (std::cos(0.1745) * upper + std::sin(0.1745) * side);
  auto v = depth_tracker::check_joint_limits(s);
  EXPECT_NEAR(v.elbow_deg, 20.0, 0.5);
  EXPECT_EQ(v.knee_back_m, 0.0);
  // Push the left knee 10 cm backwards (the person faces +z).
  s = person(0.0);
  s[JointId::LeftKnee].position.z() -= 0.10;
  v = depth_tracker::check_joint_limits(s);
  EXPECT_NEAR(v.knee_back_m, 0.08, 0.005);
  EXPECT_EQ(v.elbow_deg, 0.0);
}

TEST(DepthTracker, FitsKeepTheJointLimitsThatTheTruthKeeps) {
  // Walking and arm movements seen by one sensor: frames whose fit breaks a
  // limit (by more than a little) with the limits on and off.
  const auto broken = [](double limit_weight, const std::string& scenario) {
    sim::SimConfig cfg;
    cfg.scenario.name = scenario;
    cfg.sensors = sim::default_sensors(1);
    cfg.sensors[0].rate_hz = 20.0;  // two of every three frames of a Kinect: the same motions, fewer fits
    depth_tracker::SimDepthOptions o;
    o.intrinsics = depth::kinect_intrinsics(160, 120);
    o.girth = 1.2;
    o.tracker.limit_weight = limit_weight;
    const auto r = depth_tracker::track_simulated_depth(cfg, o);
    depth_tracker::JointLimits loose;  // what counts as broken: 5 degrees / 1 cm past the limits
    loose.min_elbow_deg -= 5;
    loose.min_knee_deg -= 5;
    loose.knee_back_m += 0.01;
    std::array<int, 2> n{};  // truth, tracked
    for (const auto& e : r.events) {
      n[e.kind == eval::TimedSkeleton::Kind::Truth ? 0 : 1] += depth_tracker::check_joint_limits(e.skeleton, loose).any();
    }
    return n;
  };
  for (const auto* scenario : {"walk", "arms"}) {
    const auto on = broken(depth_tracker::TrackerOptions{}.limit_weight, scenario);
    const auto off = broken(0.0, scenario);
    std::printf("%s: truth %d, tracked with limits %d, without %d frames breaking a limit\n", scenario, on[0], on[1],
                off[1]);
    EXPECT_EQ(on[0], 0) << scenario;  // the simulator's people keep them
    // Soft limits (penalties): a rare frame may still be past them, far fewer than without.
    EXPECT_LE(on[1], 5) << scenario;
    EXPECT_LE(20 * on[1], off[1]) << scenario;
  }
}

// A close view from the waist up (no floor in sight) of a real Kinect: both
// hands held out towards the sensor hide their forearms, and depth steps all
// round them make them regions of their own, 0.35 m from the trunk's nearest
// point. They are the person's: one group holds them, the fitted hands lie in
// them. Without joining such parts the hands are left out of the person.
TEST(DepthTracker, HandsHeldOutTowardsTheSensorAreThePersons) {
  const char* env = std::getenv("SKELGRAPH_DATA_DIR");
  const char* src = std::getenv("SKELGRAPH_SOURCE_DIR");
  const std::string file = (env ? std::string(env) : std::string(src ? src : ".") + "/../shared/data") +
                           "/skeltrack-depth/depth-data-1078881076";
  std::ifstream in(file, std::ios::binary);
  ASSERT_TRUE(in) << file << " is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)";
  auto img = depth::DepthImage::blank(depth::kinect_intrinsics(640, 480));
  std::vector<unsigned char> bytes(img.mm.size() * 2);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  ASSERT_EQ(in.gcount(), static_cast<std::streamsize>(bytes.size()));
  for (std::size_t i = 0; i < img.mm.size(); ++i) img.mm[i] = static_cast<std::uint16_t>(bytes[2 * i] | bytes[2 * i + 1] << 8);
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.translation() = Eigen::Vector3d(0, 1.2, 0);  // the tracker's default pose: level, 1.2 m up
  const auto depth_of = [&](const depth_tracker::PersonPoints& p) {
    double nearest = 1e9;
    for (const auto& q : p.points) nearest = std::min(nearest, (level.inverse() * q.cast<double>()).z());
    return nearest;
  };
  depth_tracker::TrackerOptions off;
  off.hand_reach_m = 0.0;
  const auto with = depth_tracker::find_people(img, level);
  const auto without = depth_tracker::find_people(img, level, off);
  ASSERT_EQ(with.size(), 1u);
  ASSERT_EQ(without.size(), 1u);
  EXPECT_LT(depth_of(with[0]), 0.8);     // the hands, 0.75 m from the sensor
  EXPECT_GT(depth_of(without[0]), 1.0);  // the trunk only, 1.2 m
  depth_tracker::DepthTracker tracker;
  const auto out = tracker.track(img);
  ASSERT_EQ(out.size(), 1u);
  for (const auto hand : {JointId::LeftHand, JointId::RightHand}) {
    EXPECT_LT(out[0][hand].position.z(), 0.9) << skeleton::joint_name(hand);  // the trunk is at 1.24 m
  }
  // Every joint reported lies on the person. The elbows are behind the hands,
  // hidden: without the free-space term the fit holds them out in the air in
  // front of the trunk, where the sensor would have seen them.
  const auto off_person = [&](const std::vector<skeleton::Skeleton>& people) {
    int n = 0;
    for (const auto& j : people.at(0).joints) n += j.confidence > 0 && !depth_tracker::on_surface(img, j.position);
    return n;
  };
  EXPECT_EQ(off_person(out), 0);
  depth_tracker::TrackerOptions no_free_space;
  no_free_space.free_space_weight = 0.0;
  depth_tracker::DepthTracker blind(no_free_space);
  EXPECT_GE(off_person(blind.track(img)), 2);
}

// The height of a new person is their head's top, not their raised hands'.
TEST(DepthTracker, HandsRaisedAboveTheHeadDoNotMakeThePersonTaller) {
  const auto cfg = sensor_at({0.0, 1.2, 3.0}, 180.0);
  sim::DepthRenderer r(cfg, depth::kinect_intrinsics(320, 240));
  const auto seen = [&](double elevation) {
    sim::BodyPose pose;
    pose.left_arm.elevation = pose.right_arm.elevation = elevation;
    pose.left_arm.azimuth = pose.right_arm.azimuth = M_PI / 2;
    sim::Rng rng(4);
    return depth_tracker::find_people(shot(r, {sim::forward_kinematics(sim::BodyDimensions::from_height(1.75), pose)}, rng, 0),
                                      cfg.world_from_sensor());
  };
  const auto down = seen(0.2), up = seen(2.7);  // arms hanging; raised, a little out
  ASSERT_EQ(down.size(), 1u);
  ASSERT_EQ(up.size(), 1u);
  EXPECT_GT(up[0].top, up[0].crown + 0.2);          // the region's top: the hands
  EXPECT_NEAR(up[0].crown, down[0].crown, 0.03);    // its crown: the head, as with the arms down
  EXPECT_NEAR(down[0].crown, down[0].top, 0.03);
}

// The check `skelgraph depth track` uses on real depth: a joint is on the
// person when its pixel has a reading and it is not in front of that surface.
TEST(DepthTracker, AJointIsOnTheSurfaceItsPixelShows) {
  auto img = depth::DepthImage::blank(depth::kinect_intrinsics(64, 48));
  for (int v = 10; v < 30; ++v)
    for (int u = 20; u < 40; ++u) img.mm[static_cast<std::size_t>(v) * 64 + u] = 1500;  // a patch 1.5 m away
  const Eigen::Vector3d centre = depth::unproject(img.intrinsics, 30, 20, 1.5);
  EXPECT_TRUE(depth_tracker::on_surface(img, centre));
  EXPECT_TRUE(depth_tracker::on_surface(img, centre * (1.6 / 1.5)));   // behind the surface: inside the body
  EXPECT_TRUE(depth_tracker::on_surface(img, centre * (1.46 / 1.5)));  // 4 cm in front: within the margin
  EXPECT_FALSE(depth_tracker::on_surface(img, centre * (1.3 / 1.5)));  // 20 cm in front: in the air
  EXPECT_FALSE(depth_tracker::on_surface(img, depth::unproject(img.intrinsics, 5, 5, 1.5)));    // a pixel without a reading
  EXPECT_FALSE(depth_tracker::on_surface(img, depth::unproject(img.intrinsics, -20, 20, 1.5)));  // outside the image
  EXPECT_FALSE(depth_tracker::on_surface(img, Eigen::Vector3d(0, 0, -1)));                      // behind the sensor
}

// Merged views: the lead's frame comes out with every sensor's latest of the
// same moment (within the window), in the sensors' order; others' frames
// only wait; a frame older than the window is left out.
TEST(FrameMatcher, TheLeadsFrameGathersEachSensorsLatestOfTheSameMoment) {
  depth_tracker::FrameMatcher<std::string> m(40'000'000);
  const auto image = [](int frame) {
    auto img = depth::DepthImage::blank(depth::kinect_intrinsics(8, 6));
    img.frame_number = static_cast<std::uint32_t>(frame);
    return img;
  };
  const auto frames = [](const auto& views) {
    std::vector<std::pair<std::string, int>> out;
    for (const auto& v : views) out.emplace_back(v.sensor, static_cast<int>(v.image->frame_number));
    return out;
  };
  using F = std::vector<std::pair<std::string, int>>;
  EXPECT_EQ(frames(m.add("sensor2", 0, image(1))), (F{{"sensor2", 1}}));  // the first sensor seen leads
  ASSERT_TRUE(m.lead());
  EXPECT_EQ(*m.lead(), "sensor2");
  EXPECT_TRUE(m.add("sensor1", 10'000'000, image(7)).empty());   // not the lead: kept
  EXPECT_TRUE(m.add("sensor3", 15'000'000, image(9)).empty());
  EXPECT_EQ(frames(m.add("sensor2", 33'000'000, image(2))), (F{{"sensor1", 7}, {"sensor2", 2}, {"sensor3", 9}}));
  EXPECT_TRUE(m.add("sensor1", 40'000'000, image(8)).empty());
  // Then: sensor3's frame (51 ms before) is of another moment, sensor1's newest (26 ms before) is not.
  EXPECT_EQ(frames(m.add("sensor2", 66'000'000, image(3))), (F{{"sensor1", 8}, {"sensor2", 3}}));
  // The id taken from the image moved in, in the same call (as the component does).
  depth_tracker::FrameMatcher<std::string> named(40'000'000);
  auto img = image(5);
  img.sensor_id = "sensor9";
  EXPECT_EQ(frames(named.add(img.sensor_id, 0, std::move(img))), (F{{"sensor9", 5}}));
  EXPECT_EQ(*named.lead(), "sensor9");
  // A lead given up front.
  depth_tracker::FrameMatcher<std::size_t> by_index(40'000'000, std::size_t{0});
  EXPECT_TRUE(by_index.add(1, 0, image(1)).empty());
  EXPECT_EQ(by_index.add(0, 5'000'000, image(1)).size(), 2u);
}

TEST(ImageCheck, TheNearestPersonsJointsLieOnTheImageAndAJointInTheAirDoesNot) {
  Rig rig(sensor_at({0.0, 1.2, 3.0}, 180.0));
  sim::Rng rng(3);
  const auto near = person(0.0, -0.7), far = person(0.0, 0.7);
  auto far_back = far;  // 1 m further from the sensor
  for (auto& j : far_back.joints) j.position.z() -= 1.0;
  const auto img = shot(rig.r, {near, far_back}, rng, 0);
  const Eigen::Isometry3d sensor_from_world = rig.cfg.world_from_sensor().inverse();
  std::vector<skeleton::Skeleton> tracked{far_back, near};  // the truth, as a tracker in the sensor's frame would report it
  for (auto& s : tracked) {
    s.person_id = &s == &tracked[0] ? 7 : 9;
    for (auto& j : s.joints) {
      j.position = sensor_from_world * j.position;
      j.confidence = 1.0;
    }
  }
  tracked[1].joints[static_cast<std::size_t>(JointId::RightHand)].position.z() -= 0.4;  // 40 cm in front of the body: in the air
  tracked[1].joints[static_cast<std::size_t>(JointId::Head)].confidence = 0.0;        // not reported
  const auto checked = depth_tracker::check_people(img, tracked);
  ASSERT_EQ(checked.size(), 2u);
  EXPECT_FALSE(checked[0].nearest);
  EXPECT_EQ(checked[0].person_id, 7u);
  ASSERT_TRUE(checked[1].nearest);
  EXPECT_EQ(checked[1].person_id, 9u);
  EXPECT_EQ(checked[1].joints.size(), skeleton::kJointCount - 1);
  EXPECT_EQ(checked[1].on_person, skeleton::kJointCount - 2);
  for (const auto& j : checked[1].joints) {
    EXPECT_NE(j.joint, JointId::Head);
    EXPECT_EQ(j.on_person, j.joint != JointId::RightHand) << skeleton::joint_name(j.joint);
    EXPECT_TRUE(j.pixel.x() >= 0 && j.pixel.x() < 320 && j.pixel.y() >= 0 && j.pixel.y() < 240);
  }
  EXPECT_TRUE(depth_tracker::check_people(img, {}).empty());
}

TEST(ImageCheck, BoneSpreadsGatherTheUpperBodysBonesWhereBothEndsAreReported) {
  depth_tracker::BoneSpreads spreads;
  auto s = person(0.0);
  for (auto& j : s.joints) j.confidence = 1.0;
  const double forearm = (s[JointId::RightElbow].position - s[JointId::RightHand].position).norm();
  spreads.add(s);
  s.joints[static_cast<std::size_t>(JointId::RightElbow)].position =
      s[JointId::RightHand].position + (s[JointId::RightElbow].position - s[JointId::RightHand].position) * (1.1);  // 10 % longer
  s.joints[static_cast<std::size_t>(JointId::Head)].confidence = 0.0;
  spreads.add(s);
  const auto sum = spreads.summary();
  ASSERT_EQ(sum.size(), 6u);
  EXPECT_EQ(sum.at("neck-head").images, 1u);
  EXPECT_EQ(sum.at("neck-head").sd_m, 0.0);
  const auto& f = sum.at("right_elbow-right_hand");
  EXPECT_EQ(f.images, 2u);
  EXPECT_NEAR(f.mean_m, 1.05 * forearm, 1e-12);
  EXPECT_NEAR(f.sd_m, 0.1 * forearm / std::sqrt(2.0), 1e-12);
  EXPECT_EQ(sum.at("left_shoulder-right_shoulder").images, 2u);
}
