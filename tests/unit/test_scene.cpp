// The scene for Foxglove/Lichtblick: the builder's entities and frames from
// skeletons, poses, pointing and the robot (ticks, confidence, lifetimes,
// orientations), and the CDR it writes, byte by byte for a transform. The npm
// test (scene_npm.sh) decodes whole recordings against @foxglove/schemas.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "skelgraph/scene/scene.hpp"

using namespace skelgraph::scene;
using skelgraph::skeleton::JointId;
using Eigen::Vector3d;

namespace {

skelgraph::skeleton::Skeleton person(const std::string& sensor, std::uint32_t id, double x) {
  skelgraph::skeleton::Skeleton s;
  s.sensor_id = sensor;
  s.person_id = id;
  s.frame_id = sensor;
  for (std::size_t j = 0; j < skelgraph::skeleton::kJointCount; ++j) {
    s.joints[j].position = Vector3d(x, 0.1 * static_cast<double>(j), 2.0);
    s.joints[j].confidence = skelgraph::skeleton::kTracked;
  }
  return s;
}

std::vector<Entity> entities(const std::vector<Output>& out) {
  std::vector<Entity> e;
  for (const auto& o : out)
    if (!o.is_transform) e.insert(e.end(), o.update.entities.begin(), o.update.entities.end());
  return e;
}

const Entity* find(const std::vector<Entity>& es, const std::string& id) {
  for (const auto& e : es)
    if (e.id == id) return &e;
  return nullptr;
}

}  // namespace

TEST(Scene, OneEntityPerStreamSensorAndPersonPerTick) {
  SceneBuilder b;
  const std::int64_t t0 = 1'000'000'000;
  auto s = person("sensor1", 3, 0.5);
  s[JointId::LeftHand].confidence = skelgraph::skeleton::kInferred;
  s[JointId::RightFoot].confidence = skelgraph::skeleton::kLost;
  b.add_skeleton(Stream::Raw, s, t0);
  b.add_skeleton(Stream::Raw, person("sensor1", 3, 0.6), t0 + 10'000'000);  // same tick: replaces the first
  b.add_skeleton(Stream::Raw, person("sensor1", 4, 1.0), t0 + 12'000'000);
  auto fused = person("kalman", 1, 0.55);
  fused.frame_id = "world";
  b.add_skeleton(Stream::Fused, fused, t0 + 40'000'000);  // the next tick
  auto out = b.take(t0 + 40'000'000);
  auto all = entities(out);
  ASSERT_EQ(all.size(), 2u);  // the first tick only: the second is still open
  const auto* e = find(all, "raw/sensor1/3");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->stamp_ns, t0 + 10'000'000);
  EXPECT_EQ(e->spheres.front().pose.position.x(), 0.6);
  EXPECT_EQ(e->frame_id, "sensor1");
  EXPECT_GT(e->lifetime_ns, 0);
  ASSERT_NE(find(all, "raw/sensor1/4"), nullptr);
  for (const auto& o : b.finish()) out.push_back(o);
  all = entities(out);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(find(all, "fused/kalman/1")->frame_id, "world");
  // Confidence: inferred translucent, lost left out (and its bone with it).
  SceneBuilder b2;
  b2.add_skeleton(Stream::Raw, s, t0);
  const auto one = entities(b2.finish());
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].spheres.size(), skelgraph::skeleton::kJointCount - 1);
  int translucent = 0;
  for (const auto& sp : one[0].spheres) translucent += sp.color.a < 1 ? 1 : 0;
  EXPECT_EQ(translucent, 1);
  ASSERT_EQ(one[0].lines.size(), 1u);
  EXPECT_EQ(one[0].lines[0].type, LineType::List);
  EXPECT_EQ(one[0].lines[0].points.size(), 2 * (bones().size() - 1));
}

TEST(Scene, FramesResolveToTheCellThroughThePoses) {
  SceneBuilder b;
  skelgraph::skeleton::SensorPose p;
  p.sensor_id = "sensor2";
  p.pose.translation() = Vector3d(1, 1.5, -2);
  b.add_pose(p, 5'000'000'000);
  b.add_skeleton(Stream::Raw, person("cam", 1, 0), 5'010'000'000);  // a frame without a pose
  const auto out = b.finish();
  std::map<std::string, std::string> parent;
  for (const auto& o : out)
    if (o.is_transform) parent[o.transform.child] = o.transform.parent;
  EXPECT_EQ(parent.at("world"), "cell");
  EXPECT_EQ(parent.at("sensor2"), "world");
  EXPECT_EQ(parent.at("cam"), "world");
  EXPECT_EQ(b.unplaced(), std::set<std::string>{"cam"});
  // world is y up, cell z up: world's y axis is the cell's z.
  for (const auto& o : out) {
    if (o.is_transform && o.transform.child == "world") {
      EXPECT_TRUE((o.transform.rotation * Vector3d::UnitY()).isApprox(Vector3d::UnitZ(), 1e-12));
    }
  }
  const auto es = entities(out);
  const auto* frustum = find(es, "sensor/sensor2");
  ASSERT_NE(frustum, nullptr);
  EXPECT_EQ(frustum->frame_id, "sensor2");
  EXPECT_EQ(frustum->lines.at(0).points.size(), 16u);  // 4 edges from the sensor, 4 round the far end
  // Log times never go back.
  for (std::size_t i = 1; i < out.size(); ++i) EXPECT_GE(out[i].log_ns, out[i - 1].log_ns);
}

TEST(Scene, PointingAndTheRobotAreDrawnWhereTheyAre) {
  SceneBuilder b;
  Pointing p;
  p.person_id = 2;
  p.origin = Vector3d(0, 1.4, 0);
  p.direction = Vector3d(0.6, -0.8, 0);
  p.has_target = true;
  p.target = Vector3d(1.05, 0, 0);
  b.add_pointing(p, 100);
  Capsule c{Vector3d(0, 1, 0), Vector3d(0, 1, 0.5), 0.05, "forearm"};
  b.add_robot("robot1", {c}, true, 200);
  const auto es = entities(b.finish());
  const auto* pe = find(es, "pointing/2");
  ASSERT_NE(pe, nullptr);
  ASSERT_EQ(pe->arrows.size(), 1u);
  const auto& a = pe->arrows[0];
  EXPECT_TRUE((a.pose.orientation * Vector3d::UnitX()).isApprox(p.direction.normalized(), 1e-12));
  EXPECT_NEAR(a.shaft_length + a.head_length, 1.75, 1e-12);  // to the target
  EXPECT_EQ(pe->spheres.at(0).pose.position, p.target);
  const auto* re = find(es, "robot/robot1");
  ASSERT_NE(re, nullptr);
  ASSERT_EQ(re->cylinders.size(), 1u);
  EXPECT_TRUE((re->cylinders[0].pose.orientation * Vector3d::UnitZ()).isApprox(Vector3d::UnitZ(), 1e-12));
  EXPECT_NEAR(re->cylinders[0].size.z(), 0.5, 1e-12);
  EXPECT_EQ(re->spheres.size(), 2u);
  EXPECT_EQ(re->metadata.at(1).second, "true");  // stopped
  // The monitor's verdict colours the robot and labels it above its base.
  SceneBuilder b2;
  b2.add_robot("robot1", {c}, false, 100);
  Safety s;
  s.robot_id = "robot1";
  s.state = SafetyState::Reduced;
  s.speed_scale = 0.3;
  s.separation_m = 0.92;
  s.person_id = 3;
  s.body_part = "left_hand";
  b2.add_safety(s, 200);
  b2.add_robot("robot1", {c}, false, 300);
  const auto es2 = entities(b2.finish());
  const auto* label = find(es2, "safety/robot1");
  ASSERT_NE(label, nullptr);
  ASSERT_EQ(label->texts.size(), 1u);
  EXPECT_EQ(label->texts[0].text, "reduced, speed 30 %: person 3's left_hand 0.92 m away");
  EXPECT_TRUE(label->texts[0].pose.position.isApprox(Vector3d(0, 2.3, 0)));
  const auto* amber = find(es2, "robot/robot1");  // the one after the verdict
  ASSERT_NE(amber, nullptr);
  EXPECT_EQ(amber->cylinders[0].color.r, 1.0);
  EXPECT_EQ(amber->cylinders[0].color.g, 0.7);
}

TEST(Scene, TransformCdrIsLaidOutAsTheSchemaSays) {
  FrameTransform t;
  t.stamp_ns = 3'000'000'007;
  t.parent = "cell";
  t.child = "w";
  t.translation = Vector3d(1, 2, 3);
  const auto b = to_cdr(t);
  // header | sec nsec | "cell\0" (len 5) | pad 3 | "w\0" (len 2) | pad 6 to 8 | 3 + 4 doubles
  ASSERT_EQ(b.size(), 4u + 8 + 4 + 5 + 3 + 4 + 2 + 6 + 7 * 8);
  EXPECT_EQ(b[1], 0x01);  // CDR_LE
  std::uint32_t sec = 0, nsec = 0;
  std::memcpy(&sec, &b[4], 4);
  std::memcpy(&nsec, &b[8], 4);
  EXPECT_EQ(sec, 3u);
  EXPECT_EQ(nsec, 7u);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(&b[16]), 4), "cell");
  EXPECT_EQ(b[28], 'w');
  for (std::size_t i = 29; i < 36; ++i) EXPECT_EQ(b[i], 0) << i;  // NUL and zeroed padding
  double y = 0;
  std::memcpy(&y, &b[36 + 8], 8);
  EXPECT_EQ(y, 2.0);
  EXPECT_FALSE(schema_idl("foxglove::FrameTransform").empty());
  EXPECT_THROW(schema_idl("foxglove::Nope"), std::out_of_range);
}
