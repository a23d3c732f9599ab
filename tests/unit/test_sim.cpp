// The simulator's core: scenarios, sensors, tracker model, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include "skelgraph/sim/rng.hpp"
#include "skelgraph/sim/scenario.hpp"
#include "skelgraph/sim/sensor.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/sim/tracker.hpp"

using namespace skelgraph;
using skeleton::JointId;

namespace {
double bone(const skeleton::Skeleton& s, JointId a, JointId b) { return (s[a].position - s[b].position).norm(); }
}  // namespace

TEST(SimRng, SameSeedSameNumbersAndForksAreIndependent) {
  sim::Rng a(42), b(42), c(43);
  for (int i = 0; i < 100; ++i) {
    const auto x = a.next();
    EXPECT_EQ(x, b.next());
    EXPECT_NE(x, c.next());
  }
  sim::Rng f1 = sim::Rng(7).fork(1), f2 = sim::Rng(7).fork(2);
  EXPECT_NE(f1.next(), f2.next());
  double sum = 0, sq = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double v = a.normal();
    sum += v;
    sq += v * v;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sq / n, 1.0, 0.01);
}

TEST(SimScenario, EveryScenarioRunsWithConstantBonesAndIsSeeded) {
  const auto body = sim::BodyDimensions::from_height(1.75);
  for (const auto& name : sim::scenario_names()) {
    if (name == "shift") continue;  // people come and go: SimShift below
    SCOPED_TRACE(name);
    sim::ScenarioOptions o;
    o.name = name;
    o.seed = 5;
    const sim::Scenario sc(o);
    EXPECT_GT(sc.duration(), 15.0);
    EXPECT_LT(sc.duration(), 90.0);
    std::set<std::string> phases;
    for (double t = 0; t <= sc.duration(); t += 0.1) {
      const auto scene = sc.at(t);
      ASSERT_EQ(scene.actors.size(), 1u);
      phases.insert(scene.actors[0].phase);
      const auto s = sim::forward_kinematics(body, scene.actors[0].pose);
      ASSERT_NEAR(bone(s, JointId::LeftShoulder, JointId::LeftElbow), body.upper_arm, 1e-9);
      ASSERT_NEAR(bone(s, JointId::RightElbow, JointId::RightHand), body.forearm_hand, 1e-9);
      ASSERT_NEAR(bone(s, JointId::LeftKnee, JointId::LeftFoot), body.shank, 1e-9);
      for (const auto& j : s.joints) ASSERT_GT(j.position.y(), 0.0);  // nobody goes through the floor
    }
    EXPECT_GE(phases.size(), name == "walk" || name == "tour" ? 1u : 3u);
    // Same seed: same motion; another seed: other timings.
    o.seed = 5;
    const sim::Scenario same(o);
    o.seed = 6;
    const sim::Scenario other(o);
    EXPECT_EQ(same.duration(), sc.duration());
    EXPECT_NE(other.duration(), sc.duration());
  }
  EXPECT_THROW(sim::Scenario(sim::ScenarioOptions{"dance"}), std::invalid_argument);
}

TEST(SimScenario, ScriptsDoWhatTheirNamesSay) {
  const auto body = sim::BodyDimensions::from_height(1.75);
  auto run = [](const std::string& name) {
    sim::ScenarioOptions o;
    o.name = name;
    return sim::Scenario(o);
  };
  // 360: two full turns, the first in T-pose.
  const auto turn = run("360");
  double min_h = 1e9, max_h = -1e9;
  bool t_pose_seen = false;
  for (double t = 0; t <= turn.duration(); t += 0.05) {
    const auto a = turn.at(t).actors[0];
    min_h = std::min(min_h, a.pose.heading);
    max_h = std::max(max_h, a.pose.heading);
    if (a.phase == "turn_t_pose") {
      t_pose_seen = true;
      EXPECT_NEAR(a.pose.left_arm.elevation, EIGEN_PI / 2, 1e-9);
    }
  }
  EXPECT_TRUE(t_pose_seen);
  EXPECT_NEAR(max_h - min_h, 4 * EIGEN_PI, 1e-9);

  // hide: the hidden hand is behind the back, near the spine.
  const auto hide = run("hide");
  bool checked = false;
  for (double t = 0; t <= hide.duration(); t += 0.1) {
    const auto a = hide.at(t).actors[0];
    if (a.phase != "hide_left") continue;
    const auto s = sim::forward_kinematics(body, a.pose);
    const Eigen::Vector3d fwd(std::sin(a.pose.heading), 0, std::cos(a.pose.heading));
    const Eigen::Vector3d rel = s[JointId::LeftHand].position - s[JointId::Torso].position;
    if (std::abs(a.pose.left_arm.elbow_flex - EIGEN_PI / 2) < 1e-6) {
      EXPECT_LT(rel.dot(fwd), -0.1);
      EXPECT_LT(std::abs(rel.x()), 0.12);
      checked = true;
    }
  }
  EXPECT_TRUE(checked);

  // occ: there is a wall, and the person goes behind it.
  const auto occ = run("occ");
  ASSERT_EQ(occ.at(0).obstacles.size(), 1u);
  EXPECT_EQ(occ.at(0).obstacles[0].kind, "wall");

  // box: the box starts on the floor and is held out at chest height.
  const auto box = run("box");
  double highest = 0;
  for (double t = 0; t <= box.duration(); t += 0.1) highest = std::max(highest, box.at(t).obstacles[0].box.center().y());
  EXPECT_LT(box.at(0).obstacles[0].box.center().y(), 0.2);
  EXPECT_GT(highest, 1.0);

  // sit: the hips come down to seat height.
  const auto sit = run("sit");
  double lowest_hip = 10;
  for (double t = 0; t <= sit.duration(); t += 0.1) {
    lowest_hip = std::min(lowest_hip, sim::forward_kinematics(body, sit.at(t).actors[0].pose)[JointId::LeftHip].position.y());
  }
  EXPECT_NEAR(lowest_hip, 0.50, 0.02);

  // point: both arms point, each gesture raise -> hold -> retract.
  const auto point = run("point");
  std::set<std::string> phases;
  for (double t = 0; t <= point.duration(); t += 0.05) phases.insert(point.at(t).actors[0].phase);
  EXPECT_TRUE(phases.count("raise:left") && phases.count("hold:left") && phases.count("retract:left"));
  EXPECT_TRUE(phases.count("raise:right") && phases.count("hold:right") && phases.count("retract:right"));

  // Two people: the second walks a wide circle.
  sim::ScenarioOptions two;
  two.name = "point";
  two.people = 2;
  const sim::Scenario both(two);
  const auto scene = both.at(3.0);
  ASSERT_EQ(scene.actors.size(), 2u);
  EXPECT_EQ(scene.actors[1].person_id, 2u);
  EXPECT_NEAR(scene.actors[1].pose.floor_position.norm(), 1.3, 1e-9);
}

TEST(SimSensor, DefaultSensorsLookAtTheCellFrom90DegreesApart) {
  const auto s = sim::default_sensors(2);
  ASSERT_EQ(s.size(), 2u);
  const Eigen::Vector3d centre(0, 1.2, 0);
  for (const auto& c : s) {
    const sim::SensorView v(c);
    const Eigen::Vector3d p = v.to_sensor(centre);
    EXPECT_NEAR(p.x(), 0.0, 1e-9);
    EXPECT_NEAR(p.z(), 2.0, 1e-9);  // straight ahead, 2 m
    EXPECT_TRUE(v.in_view(centre));
  }
  const Eigen::Vector3d d0 = s[0].world_from_sensor().linear().col(2), d1 = s[1].world_from_sensor().linear().col(2);
  EXPECT_NEAR(d0.dot(d1), 0.0, 1e-9);
  EXPECT_NE(s[0].clock_offset_s, s[1].clock_offset_s);
  // Sensor x is the sensor's left: for sensor1 (looking along -z) that is world -x.
  EXPECT_NEAR(sim::SensorView(s[0]).to_sensor(Eigen::Vector3d(-1, 1.2, 0)).x(), 1.0, 1e-9);
}

TEST(SimSensor, FieldOfViewRangeAndOcclusion) {
  const sim::SensorView v(sim::default_sensors(1)[0]);  // at (0, 1.2, 2) looking along -z
  EXPECT_TRUE(v.in_view({0, 1.2, 0}));
  EXPECT_FALSE(v.in_view({0, 1.2, 1.5}));   // 0.5 m: too close
  EXPECT_FALSE(v.in_view({0, 1.2, -2.5}));  // 4.5 m: too far
  const double half_h = 57.0 / 2 * EIGEN_PI / 180;
  EXPECT_TRUE(v.in_view({2.0 * std::tan(half_h) - 0.01, 1.2, 0}));
  EXPECT_FALSE(v.in_view({2.0 * std::tan(half_h) + 0.01, 1.2, 0}));
  const double half_v = 43.0 / 2 * EIGEN_PI / 180;
  EXPECT_FALSE(v.in_view({0, 1.2 + 2.0 * std::tan(half_v) + 0.01, 0}));

  const std::vector<sim::Obstacle> wall{{"wall", Eigen::AlignedBox3d(Eigen::Vector3d(-0.5, 0, 0.9), Eigen::Vector3d(0.5, 2, 1.0))}};
  double depth = 0;
  EXPECT_TRUE(v.blocked({0, 1.2, 0}, wall, &depth));
  EXPECT_NEAR(depth, 1.0, 1e-9);
  EXPECT_FALSE(v.blocked({1.5, 1.2, 0}, wall));
  EXPECT_FALSE(v.blocked({0, 1.2, 1.2}, wall));  // in front of the wall
}

TEST(SimSensor, ParsesPosesAndRejectsBadOnes) {
  const auto c = sim::parse_sensor("left:1,1.5,-2,90,10");
  EXPECT_EQ(c.id, "left");
  EXPECT_EQ(c.position, Eigen::Vector3d(1, 1.5, -2));
  EXPECT_NEAR(c.yaw, EIGEN_PI / 2, 1e-12);
  EXPECT_NEAR(c.pitch, 10 * EIGEN_PI / 180, 1e-12);
  for (const char* bad : {"1,2,3,4", "x:1,2,3", "x:1,2,three,4", "x:1,2,3,4,5,6", "x:1,2,3,nan"}) {
    EXPECT_THROW(sim::parse_sensor(bad), std::invalid_argument) << bad;
  }
  try {
    sim::parse_sensor("x:1,2,three,4");
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'three' is not a number"), std::string::npos) << e.what();
  }
}

TEST(SimSensor, FramesAt30HzWithJitterAndDrops) {
  sim::SensorConfig c;
  c.drop_probability = 0.02;
  sim::Rng rng(3);
  const auto t = sim::frame_times(c, 100.0, rng);
  EXPECT_NEAR(static_cast<double>(t.size()), 3000 * 0.98, 60);
  double worst = 0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    ASSERT_GT(t[i], t[i - 1]);
    worst = std::max(worst, t[i] - t[i - 1]);
  }
  EXPECT_GT(worst, 2.0 / 30.0 - 0.01);  // a drop leaves a gap
  c.clock_offset_s = 0.012;
  EXPECT_EQ(sim::sensor_stamp_ns(c, 1.0, 1'000'000'000), 2'012'000'000);
}

namespace {
sim::SimConfig one_sensor(const std::string& scenario, const std::string& profile, std::uint64_t seed = 1) {
  sim::SimConfig cfg;
  cfg.scenario.name = scenario;
  cfg.scenario.seed = seed;
  cfg.sensors = {sim::default_sensors(1)[0]};
  cfg.profile = profile;
  return cfg;
}
}  // namespace

TEST(SimTracker, FacingTheSensorItTracksEverythingAccurately) {
  auto cfg = one_sensor("walk", "mssdk");
  cfg.noise_scale = 0.0;
  sim::Simulation sim(cfg);
  const auto world_from_sensor = cfg.sensors[0].world_from_sensor();
  int frames = 0;
  for (const auto& e : sim.advance(sim.duration())) {
    if (e.kind != sim::SimEvent::Kind::Raw || e.t < 1.0) continue;
    ++frames;
    EXPECT_EQ(e.skeleton.frame_id, "sensor1");
    const auto truth = sim.truth_at(e.t)[0];
    for (auto j : {JointId::Torso, JointId::LeftShoulder, JointId::RightElbow}) {
      EXPECT_EQ(e.skeleton[j].confidence, skeleton::kTracked);
      // Without noise only the constant offset, the lag and the settling remain.
      EXPECT_LT((world_from_sensor * e.skeleton[j].position - truth[j].position).norm(), 0.08);
    }
  }
  EXPECT_GT(frames, 300);
}

TEST(SimTracker, BackToTheSensorFlipsLeftAndRight) {
  auto cfg = one_sensor("360", "nite");
  sim::Simulation sim(cfg);
  const auto world_from_sensor = cfg.sensors[0].world_from_sensor();
  const sim::SensorView view(cfg.sensors[0]);
  int back_frames = 0, flipped = 0, front_frames = 0, front_flipped = 0;
  for (const auto& e : sim.advance(sim.duration())) {
    if (e.kind != sim::SimEvent::Kind::Raw) continue;
    const auto scene = sim.scenario().at(e.t);
    const double angle = view.view_angle(scene.actors[0].pose);
    const auto truth = sim.truth_at(e.t)[0];
    const Eigen::Vector3d reported_left = world_from_sensor * e.skeleton[JointId::LeftShoulder].position;
    const bool swapped = (reported_left - truth[JointId::RightShoulder].position).norm() <
                         (reported_left - truth[JointId::LeftShoulder].position).norm();
    if (angle > 160 * EIGEN_PI / 180) {
      ++back_frames;
      flipped += swapped ? 1 : 0;
    } else if (angle < 20 * EIGEN_PI / 180) {
      ++front_frames;
      front_flipped += swapped ? 1 : 0;
    }
  }
  ASSERT_GT(back_frames, 30);
  EXPECT_GT(flipped, back_frames * 8 / 10);
  EXPECT_LT(front_flipped, front_frames / 10);
}

TEST(SimTracker, BehindTheWallThePersonIsLostAndComesBackWithANewId) {
  for (const std::string profile : {"mssdk", "nite"}) {
    SCOPED_TRACE(profile);
    sim::Simulation sim(one_sensor("occ", profile));
    std::set<std::uint32_t> ids;
    int hidden_frames = 0, hidden_reported = 0;
    for (const auto& e : sim.advance(sim.duration())) {
      if (e.kind != sim::SimEvent::Kind::Raw) continue;
      ids.insert(e.skeleton.person_id);
    }
    sim::Simulation again(one_sensor("occ", profile));
    std::size_t raw = 0;
    for (const auto& e : again.advance(again.duration())) raw += e.kind == sim::SimEvent::Kind::Raw ? 1 : 0;
    // Three times behind the wall: three re-acquisitions, each a new user id.
    EXPECT_EQ(ids.size(), 4u);
    // Frames without any skeleton: the person was gone.
    EXPECT_LT(raw, again.frame_count(0) * 9 / 10);
    (void)hidden_frames;
    (void)hidden_reported;
  }
}

TEST(SimTracker, HiddenJointsAreInferredByMssdkButClaimedByNite) {
  auto count = [](const std::string& profile) {
    sim::Simulation sim(one_sensor("hide", profile));
    int hidden = 0, claimed = 0;
    for (const auto& e : sim.advance(sim.duration())) {
      if (e.kind != sim::SimEvent::Kind::Raw) continue;
      const auto phase = sim.scenario().at(e.t).actors[0].phase;
      if (phase != "hide_left") continue;
      ++hidden;
      claimed += e.skeleton[JointId::LeftHand].confidence == skeleton::kTracked ? 1 : 0;
    }
    return std::pair{hidden, claimed};
  };
  const auto [ms_hidden, ms_claimed] = count("mssdk");
  const auto [nite_hidden, nite_claimed] = count("nite");
  ASSERT_GT(ms_hidden, 90);
  EXPECT_LT(ms_claimed, ms_hidden / 3);
  EXPECT_GT(nite_claimed, nite_hidden * 3 / 4);
}

// Something that is no person (a robot's link, Simulation::set_occluders)
// standing between the sensor and the person hides the joints behind it:
// the tracker loses a person hidden whole.
TEST(SimTracker, AnOccluderHidesTheJointsBehindIt) {
  auto cfg = one_sensor("walk", "mssdk");
  cfg.noise_scale = 0.0;
  const auto sensor = cfg.sensors[0].position;
  const auto hands = [&](bool occluded) {
    sim::Simulation sim(cfg);
    int frames = 0, inferred = 0;
    double nearest = 1e9;
    for (double t = 1.0; t < 6.0; t += 1.0 / 30) {
      if (occluded) {
        // A 30 cm thick pillar from the floor to 2.5 m, halfway between the sensor and the person.
        const auto person = sim.truth_at(t)[0][JointId::Torso].position;
        const Eigen::Vector3d mid = 0.5 * (sensor + person);
        sim.set_occluders({{Eigen::Vector3d(mid.x(), 0.0, mid.z()), Eigen::Vector3d(mid.x(), 2.5, mid.z()), 0.3}});
      }
      for (const auto& e : sim.advance(t)) {
        if (e.kind != sim::SimEvent::Kind::Raw) continue;
        ++frames;
        inferred += e.skeleton[JointId::Torso].confidence != skeleton::kTracked;
        nearest = std::min(nearest, e.skeleton[JointId::RightHand].position.norm());
      }
    }
    return std::tuple{frames, inferred, nearest};
  };
  const auto [clear_frames, clear_inferred, clear_nearest] = hands(false);
  const auto [hidden_frames, hidden_inferred, hidden_nearest] = hands(true);
  ASSERT_GT(clear_frames, 100);
  EXPECT_EQ(clear_inferred, 0);
  EXPECT_GT(clear_nearest, 1.0);
  // Hidden whole: the tracker loses the person (as behind the partition of `occ`), or what it
  // still reports of them lands on the pillar, nearer to the sensor.
  EXPECT_LT(hidden_frames, clear_frames / 2) << hidden_frames << " frames, nearest hand " << hidden_nearest;
  if (hidden_frames > 0) {
    EXPECT_LT(hidden_nearest, clear_nearest);
  }
  (void)hidden_inferred;
}

TEST(Simulation, SeededRunsAreBitIdenticalAndSeedsDiffer) {
  sim::SimConfig cfg;
  cfg.scenario.name = "point";
  cfg.scenario.people = 2;
  cfg.scenario.seed = 11;
  auto run = [](const sim::SimConfig& c) {
    sim::Simulation s(c);
    return s.advance(s.duration() + 1);
  };
  const auto a = run(cfg), b = run(cfg);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].t, b[i].t);
    ASSERT_EQ(a[i].skeleton.stamp_ns, b[i].skeleton.stamp_ns);
    ASSERT_EQ(a[i].skeleton.person_id, b[i].skeleton.person_id);
    for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
      ASSERT_EQ(a[i].skeleton.joints[j].position, b[i].skeleton.joints[j].position);  // exact
      ASSERT_EQ(a[i].skeleton.joints[j].confidence, b[i].skeleton.joints[j].confidence);
    }
  }
  cfg.scenario.seed = 12;
  const auto c = run(cfg);
  bool differs = c.size() != a.size();
  for (std::size_t i = 0; !differs && i < a.size(); ++i) differs = a[i].skeleton.joints[0].position != c[i].skeleton.joints[0].position;
  EXPECT_TRUE(differs);
}

TEST(Simulation, TruthAndRawInTimeOrderOnTheirOwnClocks) {
  sim::SimConfig cfg;
  cfg.scenario.name = "walk";
  cfg.epoch_ns = 5'000'000'000;
  sim::Simulation sim(cfg);
  std::size_t truth = 0;
  std::map<std::size_t, std::size_t> raw;
  double last = -1;
  // In slices, as the component does.
  for (double t = 0.1; !sim.finished(); t += 0.1) {
    for (const auto& e : sim.advance(t)) {
      ASSERT_GE(e.t, last);
      ASSERT_LT(e.t, t);
      last = e.t;
      if (e.kind == sim::SimEvent::Kind::Truth) {
        ++truth;
        EXPECT_EQ(e.skeleton.frame_id, "world");
        EXPECT_EQ(e.skeleton.stamp_ns, cfg.epoch_ns + std::llround(e.t * 1e9));
      } else {
        ++raw[e.sensor];
        const auto& sc = cfg.sensors[e.sensor];
        EXPECT_EQ(e.skeleton.sensor_id, sc.id);
        EXPECT_EQ(e.skeleton.stamp_ns, cfg.epoch_ns + std::llround((e.t + sc.clock_offset_s) * 1e9));
      }
    }
  }
  const double expected = sim.duration() * 30.0;
  EXPECT_NEAR(static_cast<double>(truth), expected, 2);
  ASSERT_EQ(raw.size(), 2u);
  // Every delivered frame has the person once tracking has begun (under a second).
  for (const auto& [sensor, n] : raw) {
    EXPECT_LE(n, sim.frame_count(sensor));
    EXPECT_GT(n + 30, sim.frame_count(sensor));
    EXPECT_NEAR(static_cast<double>(sim.frame_count(sensor)), expected * 0.99, expected * 0.02);
  }
}

TEST(Simulation, RejectsBadConfigurations) {
  sim::SimConfig cfg;
  cfg.profile = "kinect7";
  EXPECT_THROW(sim::Simulation{cfg}, std::invalid_argument);
  cfg = {};
  cfg.sensors = {};
  EXPECT_THROW(sim::Simulation{cfg}, std::invalid_argument);
  cfg = {};
  cfg.sensors[1].id = cfg.sensors[0].id;
  EXPECT_THROW(sim::Simulation{cfg}, std::invalid_argument);
}

// A working day: people come in one after another, work and leave, each
// with an id of their own; the trackers lose each one and say so.
TEST(SimShift, PeopleComeWorkAndLeaveAndEveryDepartureIsAnEvent) {
  sim::SimConfig c;
  c.scenario.name = "shift";
  c.scenario.people = 3;
  c.scenario.repeats = 4;
  c.scenario.work_s = 6.0;
  c.sensors = sim::default_sensors(3);
  c.emit_departures = true;
  sim::Simulation s(c);
  const auto& visits = s.scenario().visits();
  ASSERT_EQ(visits.size(), 12u);
  for (std::size_t i = 0; i < visits.size(); ++i) {
    EXPECT_EQ(visits[i].person_id, i + 1);  // in order of arrival
    if (i > 0) {
      EXPECT_GE(visits[i].enter, visits[i - 1].enter);
    }
    EXPECT_GT(visits[i].leave - visits[i].enter, 6.0 * 0.5);
  }
  // At most one person per place at a time, and they arrive and leave outside every view.
  for (std::size_t i = 0; i < visits.size(); ++i) {
    for (std::size_t j = i + 1; j < visits.size(); ++j) {
      if (visits[i].slot == visits[j].slot) {
        EXPECT_TRUE(visits[j].enter >= visits[i].leave || visits[i].enter >= visits[j].leave);
      }
    }
  }
  const auto body = sim::BodyDimensions::from_height(1.75);
  for (const auto& v : visits) {
    const auto scene = s.scenario().at(v.enter + 0.01);
    const auto it = std::find_if(scene.actors.begin(), scene.actors.end(), [&](const sim::Actor& a) { return a.person_id == v.person_id; });
    ASSERT_NE(it, scene.actors.end());
    EXPECT_EQ(it->slot, v.slot);
    const auto truth = sim::forward_kinematics(body, it->pose);
    for (const auto& sc : c.sensors) EXPECT_FALSE(sim::SensorView(sc).in_view(truth[JointId::Torso].position)) << v.person_id;
  }

  std::map<std::uint32_t, std::pair<double, double>> truth_span;  // first, last truth
  std::map<std::uint32_t, double> left;
  std::map<std::pair<std::size_t, std::uint32_t>, double> raw_last, lost;
  std::set<std::uint32_t> tracked_people;
  for (const auto& e : s.advance(s.duration() + 1.0)) {
    const auto id = e.skeleton.person_id;
    switch (e.kind) {
      case sim::SimEvent::Kind::Truth:
        ASSERT_FALSE(left.count(id)) << "truth of " << id << " after they left";
        if (!truth_span.count(id)) truth_span[id] = {e.t, e.t};
        truth_span[id].second = e.t;
        break;
      case sim::SimEvent::Kind::Left:
        ASSERT_TRUE(truth_span.count(id));
        ASSERT_FALSE(left.count(id)) << id << " left twice";
        left[id] = e.t;
        break;
      case sim::SimEvent::Kind::Raw:
        ASSERT_FALSE(lost.count({e.sensor, id})) << "a lost tracker user reported again";
        raw_last[{e.sensor, id}] = e.t;
        if (e.actor != 0) tracked_people.insert(e.actor);  // (0: a ghost of someone gone)
        break;
      case sim::SimEvent::Kind::Lost:
      {
        const std::pair<std::size_t, std::uint32_t> key{e.sensor, id};
        ASSERT_TRUE(raw_last.count(key));
        ASSERT_FALSE(lost.count(key));
        lost[key] = e.t;
        EXPECT_GT(e.t, raw_last[key]);
        break;
      }
      default:
        break;
    }
  }
  EXPECT_EQ(truth_span.size(), 12u);
  EXPECT_EQ(left.size(), 12u);            // everyone left, once
  EXPECT_EQ(tracked_people.size(), 12u);  // and every one was seen by a tracker
  EXPECT_EQ(lost.size(), raw_last.size());  // every tracker user ended, none left over
  for (const auto& v : visits) EXPECT_NEAR(left[v.person_id], v.leave, 0.04);
  EXPECT_GE(s.duration(), visits.back().leave + 5.0);  // the cell is empty at the end long enough to see it
  // Without emit_departures (offline tools): the same truth and raw events, none of the new kinds.
  c.emit_departures = false;
  sim::Simulation quiet(c);
  for (const auto& e : quiet.advance(quiet.duration() + 1.0)) {
    EXPECT_TRUE(e.kind == sim::SimEvent::Kind::Truth || e.kind == sim::SimEvent::Kind::Raw);
  }
}

// Layouts of a cell: every sensor 2 m from the centre, looking at it.
TEST(SimSensors, LayoutsPlaceEverySensorRoundTheCellLookingAtIt) {
  const auto angle_of = [](const sim::SensorConfig& s) { return std::atan2(s.position.x(), s.position.z()) * 180.0 / EIGEN_PI; };
  for (const auto& name : sim::layout_names()) {
    SCOPED_TRACE(name);
    const int n = name == "corners" ? 4 : 5;
    const auto sensors = sim::layout_sensors(name, n);
    ASSERT_EQ(sensors.size(), static_cast<std::size_t>(n));
    for (const auto& s : sensors) {
      EXPECT_NEAR(Eigen::Vector2d(s.position.x(), s.position.z()).norm(), 2.0, 1e-9);
      // The optical axis (+z of the sensor) points at the centre.
      const Eigen::Vector3d axis = s.world_from_sensor().linear() * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d to_centre = Eigen::Vector3d(-s.position.x(), 0, -s.position.z()).normalized();
      EXPECT_GT(axis.dot(to_centre), 0.999);
    }
  }
  const auto ring = sim::layout_sensors("ring", 6);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(std::remainder(angle_of(ring[static_cast<std::size_t>(i)]) - 60.0 * i, 360.0), 0.0, 1e-9);
  const auto side = sim::layout_sensors("one_side", 3);
  EXPECT_NEAR(angle_of(side[0]), -45.0, 1e-9);
  EXPECT_NEAR(angle_of(side[1]), 0.0, 1e-9);
  EXPECT_NEAR(angle_of(side[2]), 45.0, 1e-9);
  EXPECT_EQ(sim::layout_sensors("quarters", 3)[2].position, sim::default_sensors(3)[2].position);
  EXPECT_THROW(sim::layout_sensors("corners", 3), std::invalid_argument);
  EXPECT_THROW(sim::layout_sensors("star", 3), std::invalid_argument);
}

// A bumped sensor: before the bump its skeletons are those of an untouched
// run, after it the same person is seen from the moved sensor (its torso
// where the moved sensor's frame puts the truth, not the old one's).
TEST(SimBump, ASensorKnockedOutOfPlaceSeesFromWhereItNowIs) {
  sim::SimConfig plain;
  plain.scenario.name = "walk";
  plain.scenario.repeats = 2;
  sim::SimConfig bumped = plain;
  bumped.bumps.push_back(sim::parse_bump("sensor2,10,5,0.1"));
  sim::Simulation a(plain), b(bumped);
  const auto ea = a.advance(20), eb = b.advance(20);
  ASSERT_EQ(ea.size(), eb.size());
  sim::SensorConfig moved = plain.sensors[1];
  moved.yaw += 5 * EIGEN_PI / 180;
  moved.position += 0.1 * (plain.sensors[1].world_from_sensor().linear() * Eigen::Vector3d::UnitX());
  const sim::SensorView old_view(plain.sensors[1]), new_view(moved);
  std::size_t before = 0, after = 0;
  for (std::size_t i = 0; i < ea.size(); ++i) {
    if (ea[i].kind != sim::SimEvent::Kind::Raw || ea[i].sensor != 1) continue;
    const auto truth = a.truth_at(ea[i].t).front();
    const Eigen::Vector3d got = eb[i].skeleton[JointId::Torso].position;
    if (ea[i].t < 10) {
      EXPECT_EQ(got, ea[i].skeleton[JointId::Torso].position);
      ++before;
    } else {
      // Nearer where the moved sensor sees the truth than where the old one did.
      EXPECT_LT((got - new_view.to_sensor(truth[JointId::Torso].position)).norm(),
                (got - old_view.to_sensor(truth[JointId::Torso].position)).norm());
      ++after;
    }
  }
  EXPECT_GT(before, 200u);
  EXPECT_GT(after, 200u);
  // Bad bumps are clear errors.
  for (const auto& [spec, why] : {std::pair{"sensor2,10,5", "3 fields"}, {"sensor2,x,5,0", "'x' is not a number"},
                                  {",1,2,3", "no sensor"}, {"sensor2,-1,0,0", "negative"}}) {
    try {
      sim::parse_bump(spec);
      ADD_FAILURE() << spec << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
  sim::SimConfig nosuch = plain;
  nosuch.bumps.push_back(sim::parse_bump("sensor9,1,1,0"));
  EXPECT_THROW(sim::Simulation{nosuch}, std::invalid_argument);
}
