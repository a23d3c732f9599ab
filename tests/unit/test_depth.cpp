// Depth images, point clouds, background model, segmentation, and the
// simulator's depth renderer.
#include <gtest/gtest.h>

#include <cmath>

#include "skelgraph/depth/cloud.hpp"
#include "skelgraph/depth/depth_image.hpp"
#include "skelgraph/sim/body.hpp"
#include "skelgraph/sim/depth_render.hpp"

using namespace skelgraph;
using skeleton::JointId;

namespace {
// A flat wall `z_mm` away filling a w x h image.
depth::DepthImage wall(int w, int h, std::uint16_t z_mm) {
  auto d = depth::DepthImage::blank(depth::kinect_intrinsics(w, h));
  std::fill(d.mm.begin(), d.mm.end(), z_mm);
  return d;
}
void paint(depth::DepthImage& d, int u0, int v0, int u1, int v1, std::uint16_t z_mm) {
  for (int v = v0; v < v1; ++v)
    for (int u = u0; u < u1; ++u) d.mm[static_cast<std::size_t>(v) * d.width() + u] = z_mm;
}
// Sensor 2 m in front of the origin looking back at it (yaw 180: along -z).
sim::SensorConfig front_sensor() {
  sim::SensorConfig c;
  c.id = "front";
  c.position = {0.0, 1.2, 2.0};
  c.yaw = M_PI;
  return c;
}
}  // namespace

TEST(DepthImage, ProjectAndUnprojectAreInverseAndFollowTheSensorFrame) {
  const auto k = depth::kinect_intrinsics(320, 240);
  EXPECT_DOUBLE_EQ(k.fx, 290.0);
  EXPECT_DOUBLE_EQ(k.cx, 159.5);
  const Eigen::Vector3d p = depth::unproject(k, 10.0, 200.0, 2.5);
  EXPECT_GT(p.x(), 0.0);  // left of the image centre is the sensor's left (+x)
  EXPECT_LT(p.y(), 0.0);  // below the centre is down
  EXPECT_DOUBLE_EQ(p.z(), 2.5);
  const Eigen::Vector2d px = depth::project(k, p);
  EXPECT_NEAR(px.x(), 10.0, 1e-9);
  EXPECT_NEAR(px.y(), 200.0, 1e-9);
  const auto f = depth::intrinsics_from_fov(640, 480, 2 * std::atan(320.0 / 580.0), 2 * std::atan(240.0 / 580.0));
  EXPECT_NEAR(f.fx, 580.0, 1e-9);
  EXPECT_NEAR(f.fy, 580.0, 1e-9);
  EXPECT_THROW(depth::intrinsics_from_fov(0, 480, 1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(depth::intrinsics_from_fov(640, 480, 0.0, 1.0), std::invalid_argument);
}

TEST(DepthImage, CheckNamesWhatIsWrong) {
  auto d = wall(4, 3, 1000);
  EXPECT_NO_THROW(depth::check(d));
  d.mm.pop_back();
  try {
    depth::check(d);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("11 pixels, expected 4x3 = 12"), std::string::npos) << e.what();
  }
}

TEST(DepthCloud, PointsSkipMissingAndFarReadingsAndHonourTheStride) {
  auto d = wall(8, 6, 2000);
  d.mm[0] = 0;
  d.mm[1] = 9000;
  EXPECT_EQ(depth::to_points(d, 1, 8.0).size(), 46u);
  EXPECT_EQ(depth::to_points(d).size(), 47u);  // up to 10 m by default
  EXPECT_EQ(depth::to_points(d, 2, 8.0).size(), 11u);  // 4 x 3 sampled, the first is missing
  for (const auto& p : depth::to_points(d, 1, 8.0)) EXPECT_FLOAT_EQ(p.z(), 2.0f);
  std::vector<std::uint8_t> mask(d.mm.size(), 0);
  mask[10] = 1;
  mask[0] = 1;  // no reading there
  const auto masked = depth::to_points(d, mask);
  ASSERT_EQ(masked.size(), 1u);
  EXPECT_TRUE(masked[0].isApprox(depth::unproject(d.intrinsics, 2, 1, 2.0).cast<float>()));
}

TEST(DepthCloud, VoxelDownsampleAveragesEachCubeAndMergeMovesEachSensor) {
  depth::Points pts = {{0.01f, 0.01f, 0.01f}, {0.03f, 0.03f, 0.03f}, {0.51f, 0.0f, 0.0f}};
  const auto ds = depth::voxel_downsample(pts, 0.1);
  ASSERT_EQ(ds.size(), 2u);
  EXPECT_TRUE(ds[0].isApprox(Eigen::Vector3f(0.02f, 0.02f, 0.02f)));
  EXPECT_THROW(depth::voxel_downsample(pts, 0.0), std::invalid_argument);

  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = Eigen::Vector3d(10, 0, 0);
  const auto merged = depth::merge_clouds({{Eigen::Isometry3d::Identity(), {{0.05f, 0, 0}}}, {shift, {{-9.95f, 0, 0}}}}, 0.1);
  ASSERT_EQ(merged.size(), 1u);  // both land in the same cube
  EXPECT_NEAR(merged[0].x(), 0.05f, 1e-5);
}

TEST(DepthBackground, ForegroundIsWhatIsClearlyNearerThanTheLearntScene) {
  depth::BackgroundModel bg;
  for (int i = 0; i < 15; ++i) bg.learn(wall(40, 30, 3000));
  ASSERT_TRUE(bg.ready());
  auto frame = wall(40, 30, 3000);
  frame.mm[5] = 3050;  // noise within the margin: background
  paint(frame, 10, 10, 20, 25, 2000);
  const auto mask = bg.foreground(frame);
  std::size_t count = 0;
  for (auto m : mask) count += m;
  EXPECT_EQ(count, 150u);
  EXPECT_EQ(mask[static_cast<std::size_t>(12) * 40 + 15], 1);
  EXPECT_EQ(mask[5], 0);
  EXPECT_THROW(bg.learn(wall(20, 30, 3000)), std::invalid_argument);
}

TEST(DepthBackground, APersonStandingWhileLearningIsForgottenOnceTheyMove) {
  depth::BackgroundModel bg;
  auto with_person = wall(40, 30, 3000);
  paint(with_person, 10, 10, 20, 25, 2000);
  for (int i = 0; i < 15; ++i) bg.learn(with_person);
  EXPECT_EQ(bg.background_mm()[static_cast<std::size_t>(12) * 40 + 15], 2000);
  for (int i = 0; i < 2; ++i) bg.learn(wall(40, 30, 3000));
  EXPECT_EQ(bg.background_mm()[static_cast<std::size_t>(12) * 40 + 15], 2000);  // not yet: 2 frames
  bg.learn(wall(40, 30, 3000));
  EXPECT_EQ(bg.background_mm()[static_cast<std::size_t>(12) * 40 + 15], 3000);  // confirmed on the third
  const auto mask = bg.foreground(with_person);
  EXPECT_EQ(mask[static_cast<std::size_t>(12) * 40 + 15], 1);
}

TEST(DepthSegment, RegionsSplitAtDepthStepsAndSmallOnesAreDropped) {
  auto d = wall(60, 40, 3000);
  paint(d, 5, 5, 20, 35, 2000);   // 450 px
  paint(d, 20, 5, 30, 35, 2500);  // touching, 0.5 m behind: another region (300 px)
  paint(d, 40, 5, 45, 10, 1500);  // 25 px: dropped
  std::vector<std::uint8_t> mask(d.mm.size(), 0);
  for (std::size_t i = 0; i < d.mm.size(); ++i) mask[i] = d.mm[i] < 3000;
  const auto seg = depth::segment(d, mask, 0.08, 100);
  ASSERT_EQ(seg.regions.size(), 2u);
  EXPECT_EQ(seg.regions[0].pixels, 450u);
  EXPECT_EQ(seg.regions[1].pixels, 300u);
  EXPECT_NEAR(seg.regions[0].centroid.z(), 2.0, 1e-9);
  EXPECT_EQ(seg.labels[static_cast<std::size_t>(7) * 60 + 42], 0u);  // the small blob
  EXPECT_EQ(seg.labels[static_cast<std::size_t>(10) * 60 + 10], seg.regions[0].label);
  // With a generous step the two touch and become one.
  EXPECT_EQ(depth::segment(d, mask, 0.6, 100).regions.size(), 1u);
}

TEST(DepthRender, FloorAndWallsLieWhereGeometrySaysAndPropsOcclude) {
  const auto k = depth::kinect_intrinsics(160, 120);
  sim::DepthRenderer r(front_sensor(), k, {}, {});
  const auto exact = r.render_exact({}, {});
  // Centre pixel: straight ahead along -z to the wall at z = -4: 6 m.
  const auto centre = static_cast<std::size_t>(60) * 160 + 80;
  EXPECT_NEAR(exact[centre - 80 + 79], 6.0, 0.05);
  // Bottom row: the floor, y = 0 in the world.
  const Eigen::Isometry3d world_from_sensor = front_sensor().world_from_sensor();
  for (int u : {10, 80, 150}) {
    const float z = exact[static_cast<std::size_t>(119) * 160 + u];
    ASSERT_GT(z, 0.0f);
    const Eigen::Vector3d p = world_from_sensor * depth::unproject(k, u, 119, z);
    EXPECT_NEAR(p.y(), 0.0, 1e-6) << u;
  }
  // A box between the sensor and the wall: the centre now sees its front face at z = 1.
  sim::Obstacle box{"box", Eigen::AlignedBox3d(Eigen::Vector3d(-0.5, 0.0, 0.0), Eigen::Vector3d(0.5, 2.0, 1.0))};
  const auto occluded = r.render_exact({}, {box});
  EXPECT_NEAR(occluded[static_cast<std::size_t>(60) * 160 + 79], 1.0, 1e-6);
}

TEST(DepthRender, ThePersonsPointsLieOnTheirBodyCapsules) {
  const auto k = depth::kinect_intrinsics(320, 240);
  sim::DepthRenderer r(front_sensor(), k, {}, {});
  sim::BodyPose pose;
  pose.heading = 0.0;  // faces +z, the sensor
  pose.right_arm = sim::arm_side();
  const auto person = sim::forward_kinematics(sim::BodyDimensions::from_height(1.75), pose);
  const auto exact = r.render_exact({person}, {});
  const auto background = r.render_exact({}, {});
  const auto caps = sim::body_capsules(person);
  const Eigen::Isometry3d world_from_sensor = front_sensor().world_from_sensor();
  std::size_t body_pixels = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    if (exact[i] >= background[i] - 1e-6f) continue;
    ++body_pixels;
    const int u = static_cast<int>(i % 320), v = static_cast<int>(i / 320);
    const Eigen::Vector3d p = world_from_sensor * depth::unproject(k, u, v, exact[i]);
    double nearest = 1e9;  // distance to the nearest capsule's surface
    for (const auto& c : caps) {
      const Eigen::Vector3d ba = c.b - c.a;
      const double s = ba.squaredNorm() > 0 ? std::clamp((p - c.a).dot(ba) / ba.squaredNorm(), 0.0, 1.0) : 0.0;
      nearest = std::min(nearest, std::abs((p - (c.a + s * ba)).norm() - c.radius));
    }
    ASSERT_LT(nearest, 1e-3) << "pixel " << u << "," << v;
  }
  // At 2 m a standing person covers several thousand pixels of a 320x240 image.
  EXPECT_GT(body_pixels, 3000u);
  EXPECT_LT(body_pixels, 20000u);
  // The head is seen right in front of its centre: depth = distance - radius.
  const Eigen::Vector3d head = r.view().to_sensor(person[JointId::Head].position);
  const Eigen::Vector2d px = depth::project(k, head);
  const auto hi = static_cast<std::size_t>(std::lround(px.y())) * 320 + static_cast<std::size_t>(std::lround(px.x()));
  EXPECT_NEAR(exact[hi], head.z() - 0.095, 0.01);
}

TEST(DepthRender, KinectNoiseGrowsWithDepthSquaredAndIsDeterministic) {
  const auto k = depth::kinect_intrinsics(160, 120);
  sim::DepthNoise noise;
  noise.random_drop = 0.0;
  // A sensor looking straight at a wall at 1.5 m and one at 3.5 m (room walls at +-4 m).
  auto at = [&](double z) {
    sim::SensorConfig c = front_sensor();
    c.position = {0.0, 1.5, -4.0 + z};
    sim::DepthRenderer r(c, k, noise, {});
    sim::Rng rng(3);
    const auto img = r.render({}, {}, rng);
    const auto exact = r.render_exact({}, {});
    double sq = 0;
    int n = 0;
    for (int v = 50; v < 70; ++v)
      for (int u = 70; u < 90; ++u) {
        const auto i = static_cast<std::size_t>(v) * 160 + u;
        if (img.mm[i] == 0) continue;
        sq += std::pow(img.mm[i] * 1e-3 - exact[i], 2);
        ++n;
      }
    EXPECT_EQ(n, 400);
    return std::sqrt(sq / n);
  };
  const double near = at(1.5), far = at(3.5);
  EXPECT_GT(near, 0.001);
  EXPECT_LT(near, 0.01);
  EXPECT_GT(far / near, 3.0);  // (3.5 / 1.5)^2 = 5.4; quantisation makes it uneven
  EXPECT_LT(far, 0.06);
  // Same seed, same image; another seed, another image.
  sim::DepthRenderer r(front_sensor(), k, noise, {});
  sim::Rng a(9), b(9), c(10);
  EXPECT_EQ(r.render({}, {}, a).mm, r.render({}, {}, b).mm);
  sim::Rng d(9);
  EXPECT_NE(r.render({}, {}, d).mm, r.render({}, {}, c).mm);
}

TEST(DepthRender, DepthEdgesLoseReadingsAndRangeLimitsApply) {
  const auto k = depth::kinect_intrinsics(160, 120);
  sim::DepthNoise noise;
  noise.random_drop = 0.0;
  sim::DepthRenderer r(front_sensor(), k, noise, {});
  sim::Obstacle post{"box", Eigen::AlignedBox3d(Eigen::Vector3d(-0.2, 0.0, -0.2), Eigen::Vector3d(0.2, 3.0, 0.2))};
  sim::Rng rng(1);
  const auto img = r.render({}, {post}, rng);
  const auto exact = r.render_exact({}, {post});
  int edge = 0, edge_missing = 0;
  for (int v = 1; v < 119; ++v)
    for (int u = 1; u < 159; ++u) {
      const auto i = static_cast<std::size_t>(v) * 160 + u;
      const bool is_edge = exact[i - 1] < exact[i] - 0.05f || exact[i + 1] < exact[i] - 0.05f;
      if (is_edge) {
        ++edge;
        edge_missing += img.mm[i] == 0;
      }
    }
  ASSERT_GT(edge, 50);
  EXPECT_GT(edge_missing, edge / 4);
  EXPECT_LT(edge_missing, edge * 3 / 4);
  // Out of range: the wall 6 m away has no readings when the range ends at 5 m.
  noise.max_range_m = 5.0;
  sim::DepthRenderer short_range(front_sensor(), k, noise, {});
  const auto clipped = short_range.render({}, {post}, rng);
  int far = 0, far_missing = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    if (exact[i] < 5.5f) continue;
    ++far;
    far_missing += clipped.mm[i] == 0;
  }
  ASSERT_GT(far, 1000);
  EXPECT_EQ(far_missing, far);
  EXPECT_THROW(sim::DepthRenderer(front_sensor(), depth::kinect_intrinsics(0, 0)), std::invalid_argument);
}
