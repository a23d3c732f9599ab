// Live spotting: rays meeting surfaces, surface parsing, the pointing
// correction, scoring against truth by hand-counted cases, and the spotter on
// simulated sessions it was not trained on (pointing found, its target near
// the true one, waves and stretches mostly left alone).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "skelgraph/gesture/sim_sessions.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/sim/tracker.hpp"

using namespace skelgraph::gesture;
using Eigen::Vector3d;
using skelgraph::skeleton::JointId;

TEST(Pointing, RaysMeetTheFloorOnlyGoingDown) {
  const Surface floor;
  const auto hit = intersect({0, 1.5, 0}, Vector3d(1, -1, 0).normalized(), floor);
  ASSERT_TRUE(hit);
  EXPECT_NEAR((*hit - Vector3d(1.5, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_FALSE(intersect({0, 1.5, 0}, {1, 0, 0}, floor));                      // parallel
  EXPECT_FALSE(intersect({0, 1.5, 0}, Vector3d(1, 1, 0).normalized(), floor));  // up, away from it
  const auto table = parse_surface("table:0,0.75,0");
  EXPECT_EQ(table.name, "table");
  EXPECT_NEAR(intersect({0, 1.5, 0}, Vector3d(1, -1, 0).normalized(), table)->x(), 0.75, 1e-12);
  const auto wall = parse_surface("wall:0,0,3:0,0,-2");
  EXPECT_NEAR(wall.normal.z(), -1.0, 1e-12);
  EXPECT_NEAR(intersect({0, 1.5, 0}, {0, 0, 1}, wall)->z(), 3.0, 1e-12);
  for (const char* bad : {"floor", ":0,0,0", "floor:0,0", "floor:0,0,x", "wall:0,0,3:0,0,0"}) {
    EXPECT_THROW(parse_surface(bad), std::invalid_argument) << bad;
  }
}

TEST(Pointing, CorrectionTurnsTheRayByTheGivenAngles) {
  const Vector3d out(1, 0, 0);  // the right arm of a person facing -z... or +z: only differences matter
  const Vector3d d = Vector3d(0.3, -0.6, 0.7).normalized();
  const PointingCorrection c{4.0, -2.5};
  const Vector3d e = corrected(d, out, c);
  EXPECT_NEAR(e.norm(), 1.0, 1e-12);
  const auto off = ray_offset(e, d, out);
  EXPECT_NEAR(off.elevation, -4.0, 1e-9);  // lowered by 4 degrees
  EXPECT_NEAR(off.azimuth_out, 2.5, 1e-9);  // turned out by 2.5 (a correction of -2.5 inwards)
  EXPECT_NEAR((corrected(d, out, {}) - d).norm(), 0.0, 1e-12);
}

TEST(Spotting, ScoresMatchHandCountedCases) {
  const auto ms = [](double s) { return static_cast<std::int64_t>(s * 1e9); };
  std::vector<TruthGesture> truth(3);
  truth[0] = {"point", ms(1), ms(4), ms(2), true, {1, 0, 1}, false, {}, {}};
  truth[1] = {"point", ms(10), ms(13), ms(11), true, {0, 0, 2}, false, {}, {}};
  truth[2] = {"wave", ms(20), ms(23), -1, false, {}, false, {}, {}};
  std::vector<SpottedEvent> events(4);
  events[0].label = "point", events[0].end_ns = ms(2.5), events[0].has_target = true, events[0].target = {1.1, 0, 1};
  events[1].label = "point", events[1].end_ns = ms(3.0);  // the same gesture again: a false positive
  events[2].label = "point", events[2].end_ns = ms(21);   // during the wave
  events[3].label = "wave", events[3].end_ns = ms(23.2);
  const auto r = score_spotting(events, truth, "point");
  EXPECT_EQ(r.truth, 2);
  EXPECT_EQ(r.events, 3);
  EXPECT_EQ(r.true_positive, 1);
  EXPECT_EQ(r.false_positive, 2);
  EXPECT_EQ(r.false_negative, 1);
  EXPECT_DOUBLE_EQ(r.precision, 1.0 / 3);
  EXPECT_DOUBLE_EQ(r.recall, 0.5);
  ASSERT_EQ(r.latency_s.size(), 1u);
  EXPECT_NEAR(r.latency_s[0], -1.5, 1e-9);
  EXPECT_NEAR(r.latency_hold_s[0], 0.5, 1e-9);
  EXPECT_NEAR(r.target_error_m[0], 0.1, 1e-9);
  const auto w = score_spotting(events, truth, "wave");
  EXPECT_EQ(w.true_positive, 1);  // 0.2 s after the end is within the slack
  const auto both = combine({r, w});
  EXPECT_EQ(both.true_positive, 2);
  EXPECT_EQ(both.truth, 3);
  EXPECT_EQ(both.latency_s.size(), 2u);
}

TEST(Spotting, FindsPointingInHeldOutSimulatedSessions) {
  std::size_t clips = 0;
  const auto model = train_on_sim(4, 3, sim_classifier_options(), &clips);
  EXPECT_GT(clips, 50u);
  EXPECT_NE(model.pointing_correction().elevation, 0.0);  // learnt, not left at zero
  // The joint offsets learnt against the truth are the simulated tracker's
  // skeleton convention (NITE's shoulder and hand offsets in the body frame).
  const auto& nite = skelgraph::sim::TrackerProfile::by_name("nite");
  for (const auto& [learnt, joint] : {std::pair{model.pointing_correction().shoulder, JointId::RightShoulder},
                                      std::pair{model.pointing_correction().hand, JointId::RightHand}}) {
    const Vector3d truth = nite.offset[static_cast<std::size_t>(joint)];
    EXPECT_LT((learnt - truth).norm(), 0.015) << skelgraph::skeleton::joint_name(joint) << ": " << learnt.transpose();
  }
  std::vector<SpottingReport> reports;
  std::set<MotionState> states;
  for (std::uint64_t seed : {901, 902}) {
    const auto session = simulate_session(seed);
    std::map<std::uint32_t, Spotter> spotters;
    std::vector<SpottedEvent> events;
    for (const auto& f : session.fused) {
      auto& sp = spotters.try_emplace(f.person_id, model).first->second;
      for (const auto& e : sp.step(f)) events.push_back(e);
      states.insert(sp.state());
    }
    for (const auto& e : events) {
      EXPECT_GE(e.end_ns, e.start_ns);
      EXPECT_GE(e.confidence, 0.0);
      EXPECT_LE(e.confidence, 1.0);
      if (e.has_target) {
        EXPECT_NEAR(e.target.y(), 0.0, 1e-9);
      }
    }
    reports.push_back(score_spotting(events, session.truth, "point"));
  }
  const auto r = combine(reports);
  EXPECT_EQ(r.truth, 12);  // 6 pointing gestures per session
  EXPECT_GE(r.recall, 0.8);
  EXPECT_GE(r.precision, 0.6);
  ASSERT_GE(r.target_error_m.size(), 8u);
  EXPECT_LT(r.median_target_error_m, 0.4);
  // Sent once the ray has been gathered over the hold (up to `aim`, 1.5 s), and
  // before the arm is back down.
  EXPECT_GT(r.median_latency_hold_s, 0.25);
  EXPECT_LT(r.median_latency_hold_s, SpotterOptions{}.aim + 0.2);
  EXPECT_LT(r.median_latency_s, 0.0);
  EXPECT_EQ(states.size(), 3u);             // resting, moving and holding all seen
  // aim <= hold: the event goes out as soon as pointing is decided, from a quarter-second look.
  SpotterOptions at_once;
  at_once.aim = 0.0;
  const auto quick = combine({spot_sessions(model, {simulate_session(901)}, at_once)[0].report});
  EXPECT_GE(quick.true_positive, 4);
  EXPECT_LT(quick.median_latency_hold_s, 0.8);
  EXPECT_LT(quick.median_latency_hold_s, r.median_latency_hold_s - 0.5);
}
