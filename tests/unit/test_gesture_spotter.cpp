// Live spotting: rays meeting surfaces, surface parsing, the pointing
// correction, scoring against truth by hand-counted cases, and the spotter on
// simulated sessions it was not trained on (pointing found, its target near
// the true one, waves and stretches mostly left alone).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <functional>
#include <map>
#include <set>

#include "skelgraph/gesture/builtin_models.hpp"
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

namespace {

// One-state diagonal models on the clips as they are (no trimming, no inner folds).
Classifier one_state(const std::vector<Clip>& clips, const ClassMap& map) {
  ClassifierOptions o;
  o.hmm.states = 1;
  o.hmm.covariance = Covariance::Diagonal;
  o.trimmed = false;
  o.calibration_folds = 0;
  return Classifier::train(clips, map, o);
}

// A classifier with "point" as its only class that never rejects: every
// segment the spotter tries is pointing, so the tests below see exactly
// when the spotter tries (the classifier is not what they are about).

// A classifier of one class that never rejects: every segment is that class.
Classifier always(const std::string& label) {
  std::vector<Clip> clips;
  for (int i = 0; i < 4; ++i) {
    Clip c;
    c.label = 0;
    c.x = Sequence::Random(30, 8);
    clips.push_back(c);
  }
  ClassMap map;
  map.classes = {label};
  Classifier c = one_state(clips, map);
  c.set_threshold(-1e300);
  return c;
}
Classifier always_point() { return always("point"); }

// A person at the origin facing +z, arms straight, the left one hanging; the
// right one raised forward by raise(t) degrees from hanging, at 30 Hz from
// 0 to `until` s, leaving out the frames in [gap_from, gap_to).
std::vector<skelgraph::skeleton::Skeleton> arm_stream(const std::function<double(double)>& raise, double until,
                                                      double gap_from = -1, double gap_to = -1) {
  std::vector<skelgraph::skeleton::Skeleton> out;
  for (int i = 0; i / 30.0 <= until; ++i) {
    const double t = i / 30.0;
    if (t >= gap_from && t < gap_to) continue;
    skelgraph::skeleton::Skeleton s;
    s.person_id = 1;
    s.frame_id = "world";
    s.stamp_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
    const auto set = [&](JointId j, const Vector3d& p) {
      s[j].position = p;
      s[j].confidence = skelgraph::skeleton::kTracked;
    };
    set(JointId::Head, {0, 1.7, 0});
    set(JointId::Neck, {0, 1.5, 0});
    set(JointId::Torso, {0, 1.2, 0});
    set(JointId::LeftShoulder, {-0.2, 1.45, 0});
    set(JointId::LeftElbow, {-0.2, 1.15, 0});
    set(JointId::LeftHand, {-0.2, 0.85, 0});
    const double a = raise(t) * M_PI / 180;
    const Vector3d sh(0.2, 1.45, 0), dir(0, -std::cos(a), std::sin(a));
    set(JointId::RightShoulder, sh);
    set(JointId::RightElbow, sh + 0.3 * dir);
    set(JointId::RightHand, sh + 0.6 * dir);
    out.push_back(s);
  }
  return out;
}

// The tests here are not about where the ray lands: any ray counts unless a test says otherwise.
SpotterOptions any_ray() {
  SpotterOptions o;
  o.max_target = 0;
  return o;
}

std::vector<SpottedEvent> spot(const Classifier& c, const std::vector<skelgraph::skeleton::Skeleton>& stream,
                               const SpotterOptions& o = any_ray()) {
  Spotter sp(c, o);
  std::vector<SpottedEvent> events;
  for (const auto& s : stream) {
    for (auto& e : sp.step(s)) events.push_back(e);
  }
  return events;
}

// Rest, raise over 0.5 s from `from`, hold `angle` degrees for 3 s, lower, rest.
std::function<double(double)> gesture(double from, double angle) {
  return [=](double t) {
    const double u = std::clamp((t - from) / 0.5, 0.0, 1.0) - std::clamp((t - from - 3.5) / 0.5, 0.0, 1.0);
    return angle * u;
  };
}

}  // namespace

TEST(Spotting, PointingLandsWithinReachAndLeavesTheOtherArmFree) {
  const auto c = always_point();
  EXPECT_EQ(SpotterOptions{}.max_target, 0.0);  // off unless the surfaces are known (gesture spot on recordings)
  SpotterOptions defaults;
  defaults.max_target = 4.0;  // the cell's (sim_spotter_options(), the gesture component)
  // 70 degrees up from hanging from 1.45 m: the floor 4.2 m from the shoulder, beyond 4 m.
  EXPECT_TRUE(spot(c, arm_stream(gesture(2.0, 70), 8), defaults).empty());
  // 55 degrees: 2.5 m away, an event with its target.
  const auto near = spot(c, arm_stream(gesture(2.0, 55), 8), defaults);
  ASSERT_EQ(near.size(), 1u);
  ASSERT_TRUE(near[0].has_target);
  EXPECT_LT((near[0].target - near[0].ray_origin).norm(), 4.0);
  // Both arms held out the same way (carrying, a stretch): no pointing; allowed when other_arm_free is off.
  auto both = arm_stream(gesture(2.0, 55), 8);
  for (auto& s : both) {
    const Vector3d d = s[JointId::RightHand].position - s[JointId::RightShoulder].position;
    s[JointId::LeftElbow].position = s[JointId::LeftShoulder].position + 0.5 * d;
    s[JointId::LeftHand].position = s[JointId::LeftShoulder].position + d;
  }
  EXPECT_TRUE(spot(c, both, defaults).empty());
  SpotterOptions allow = defaults;
  allow.other_arm_free = false;
  EXPECT_EQ(spot(c, both, allow).size(), 1u);
}

TEST(Spotting, PointingIsAStraightArmFromAnUprightTrunk) {
  const auto c = always_point();
  EXPECT_EQ(SpotterOptions{}.min_straightness, 0.90);  // on everywhere: it needs no frame
  EXPECT_EQ(SpotterOptions{}.max_lean_m, 0.0);         // needs a level world: the cell's, not a recording's camera
  EXPECT_EQ(skelgraph::gesture::sim_spotter_options().max_lean_m, 0.07);
  SpotterOptions o = any_ray();
  o.max_lean_m = 0.07;
  // Straight and upright: pointing, its straightness and lean reported.
  const auto straight = spot(c, arm_stream(gesture(2.0, 55), 8), o);
  ASSERT_EQ(straight.size(), 1u);
  EXPECT_NEAR(straight[0].straightness, 1.0, 1e-9);
  EXPECT_NEAR(straight[0].lean_m, 0.0, 1e-9);
  // The elbow bent by 60 degrees (shoulder to hand 0.87 of the arm): a reach, not pointing.
  auto bent = arm_stream(gesture(2.0, 55), 8);
  for (auto& s : bent) {
    const Vector3d sh = s[JointId::RightShoulder].position, el = s[JointId::RightElbow].position;
    const Vector3d upper = el - sh;
    const Eigen::AngleAxisd turn(-60 * M_PI / 180, Vector3d::UnitX());  // the forearm up: still raised above 35 degrees
    s[JointId::RightHand].position = el + turn * upper;
  }
  const double bent_share = (bent[200][JointId::RightHand].position - bent[200][JointId::RightShoulder].position).norm() / 0.6;
  ASSERT_NEAR(bent_share, std::cos(30 * M_PI / 180), 1e-6);
  EXPECT_TRUE(spot(c, bent, o).empty());
  SpotterOptions any_arm = o;
  any_arm.min_straightness = 0;
  EXPECT_EQ(spot(c, bent, any_arm).size(), 1u);
  // Leaning forward to a bench: the neck 15 cm ahead of the torso.
  auto leaning = arm_stream(gesture(2.0, 55), 8);
  for (auto& s : leaning) s[JointId::Neck].position.z() += 0.15;
  EXPECT_TRUE(spot(c, leaning, o).empty());
  EXPECT_EQ(spot(c, leaning, any_ray()).size(), 1u);  // lean not asked for (a recording's tilted camera)
  auto slight = arm_stream(gesture(2.0, 55), 8);
  for (auto& s : slight) s[JointId::Neck].position.x() += 0.05;  // 5 cm: within the tracker's error of upright
  EXPECT_EQ(spot(c, slight, o).size(), 1u);
}

TEST(Spotting, AConfirmationDropsPointingHeldBriefly) {
  const auto c = always_point();
  // Raised over 0.5 s to 55 degrees at 2 s, held `hold` s, lowered over 0.5 s.
  const auto brief = [](double hold) {
    return [hold](double t) {
      const double u = std::clamp((t - 2.0) / 0.5, 0.0, 1.0) - std::clamp((t - 2.5 - hold) / 0.5, 0.0, 1.0);
      return 55.0 * u;
    };
  };
  SpotterOptions o = any_ray();
  EXPECT_EQ(spot(c, arm_stream(brief(0.8), 6), o).size(), 1u);  // no confirmation: held 0.8 s is pointing
  o.confirm = 1.0;
  EXPECT_TRUE(spot(c, arm_stream(brief(0.8), 6), o).empty());  // 0.25 + 1.0 s needed
  const auto long_hold = spot(c, arm_stream(brief(2.5), 8), o);
  ASSERT_EQ(long_hold.size(), 1u);                               // held long enough: still sent
  EXPECT_TRUE(long_hold[0].has_ray);
}

// A held gesture other than pointing (a raised palm: "stop") goes out once
// held `hold` s, without a ray, not when the arm comes down.
TEST(Spotting, AHeldStopGoesOutWhileTheArmIsStillUp) {
  const Classifier c = always("stop");
  // The arm up at 90 degrees from 2.0 to 2.5 s, held until 5.5 s, down by 6 s.
  const auto held = [](double t) {
    return 90.0 * (std::clamp((t - 2.0) / 0.5, 0.0, 1.0) - std::clamp((t - 5.5) / 0.5, 0.0, 1.0));
  };
  const auto early = spot(c, arm_stream(held, 9), any_ray());
  ASSERT_EQ(early.size(), 1u);
  EXPECT_EQ(early[0].label, "stop");
  EXPECT_FALSE(early[0].has_ray);
  EXPECT_LT(early[0].end_ns * 1e-9, 3.5);  // still held (until 5.5 s)
  SpotterOptions late = any_ray();
  late.held_labels.clear();
  const auto at_end = spot(c, arm_stream(held, 9), late);
  ASSERT_EQ(at_end.size(), 1u);
  EXPECT_GT(at_end[0].end_ns * 1e-9, 6.0);  // once the arm is down and rested
}

TEST(Spotting, AHangingArmIsNoPointing) {
  const auto c = always_point();
  // Pointing at the floor ahead (70 degrees up from hanging): one event, its ray that way.
  const auto held = spot(c, arm_stream(gesture(2.0, 70), 8));
  ASSERT_EQ(held.size(), 1u);
  ASSERT_TRUE(held[0].has_ray);
  EXPECT_NEAR(std::acos(-held[0].ray_direction.y()) * 180 / M_PI, 70.0, 1.0);
  // An arm hanging 25 degrees out (a tracker's error, a hand on a hip) is
  // outside the rest zone and extended; it is no pointing...
  EXPECT_TRUE(spot(c, arm_stream(gesture(2.0, 25), 8)).empty());
  // ...which only min_raise says: without it the same stream points at the feet.
  SpotterOptions any_angle;
  any_angle.min_raise = 0;
  EXPECT_EQ(spot(c, arm_stream(gesture(2.0, 25), 8), any_angle).size(), 1u);
}

// With a garbage class, the garbage model is the spotter's "no gesture": a
// pointing its model wins goes out even below the rejection threshold;
// without one, the threshold decides.
TEST(Spotting, TheGarbageClassNotTheThresholdRejects) {
  std::vector<Clip> clips;
  for (int i = 0; i < 4; ++i) {
    Clip point, other;
    point.label = 0;
    point.x = Sequence::Random(30, 8);
    other.label = 1;  // far from any arm's features: the point model always wins
    other.x = Sequence::Constant(30, 8, 100.0) + 0.01 * Sequence::Random(30, 8);
    clips.push_back(point);
    clips.push_back(other);
  }
  ClassMap map;
  map.classes = {"point", "other"};
  map.garbage = "other";
  Classifier with_garbage = one_state(clips, map);
  with_garbage.set_threshold(1e300);  // every decision is below it
  const auto stream = arm_stream(gesture(2.0, 70), 8);
  ASSERT_EQ(spot(with_garbage, stream).size(), 1u);
  auto no_garbage = always_point();
  EXPECT_EQ(spot(no_garbage, stream).size(), 1u);
  no_garbage.set_threshold(1e300);
  EXPECT_TRUE(spot(no_garbage, stream).empty());
  // The garbage model winning is still no event, whatever the threshold.
  for (auto& c : clips) c.label = 1 - c.label;  // now the point model is the far one
  Classifier garbage_wins = one_state(clips, map);
  garbage_wins.set_threshold(-1e300);
  EXPECT_TRUE(spot(garbage_wins, stream).empty());
}

TEST(Spotting, APersonLostAndFoundSettlesAgain) {
  const auto c = always_point();
  const SpotterOptions o;
  // The arm is up from 2.1 s, still by the hand's speed (over `window` s,
  // smoothed) about 0.3 s later: the event goes out `aim` s after that.
  const auto plain = spot(c, arm_stream(gesture(1.6, 70), 8));
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_NEAR(plain[0].end_ns * 1e-9, 2.1 + 0.3 + o.aim, 0.1);
  // The same with the person unseen from 1.0 to 1.6 s (lost by the trackers,
  // found again under the same id): the hold counts only once the fresh
  // skeletons have had `warmup` s to settle.
  const auto after_gap = spot(c, arm_stream(gesture(1.6, 70), 8, 1.0, 1.6));
  ASSERT_EQ(after_gap.size(), 1u);
  EXPECT_NEAR(after_gap[0].end_ns * 1e-9, 1.6 + o.warmup + o.aim, 0.05);
  // A gap shorter than `lost` (dropped frames) changes nothing.
  const auto short_gap = spot(c, arm_stream(gesture(1.6, 70), 8, 1.0, 1.2));
  ASSERT_EQ(short_gap.size(), 1u);
  EXPECT_EQ(short_gap[0].end_ns, plain[0].end_ns);
}

// The built-in model the launch files' `model: sim` loads, trained by the
// build: a pointing classifier that finds pointing in sessions it never saw,
// and a clear error naming the file when it is missing.
TEST(BuiltinModel, TheBuildsSimModelSpotsPointing) {
  ASSERT_TRUE(is_builtin_model("sim"));
  EXPECT_FALSE(is_builtin_model("sim.json"));
  const auto model = load_builtin_model("sim");
  const auto& labels = model.labels();
  EXPECT_NE(std::find(labels.begin(), labels.end(), "point"), labels.end());
  const auto spotted = spot_sessions(model, held_out_sessions(1, 77));
  ASSERT_EQ(spotted.size(), 1u);
  EXPECT_EQ(spotted[0].report.truth, 6);
  EXPECT_GE(spotted[0].report.recall, 0.8);
}

TEST(BuiltinModel, AMissingModelNamesItsFileAndTheBuildTarget) {
  const std::string before = builtin_model_dir().string();
  ::setenv("SKELGRAPH_MODEL_DIR", "/nonexistent/models", 1);
  try {
    load_builtin_model("sim");
    ADD_FAILURE() << "no error for a missing model";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/nonexistent/models/sim.json"), std::string::npos) << what;
    EXPECT_NE(what.find("gesture_models"), std::string::npos) << what;
  }
  ::unsetenv("SKELGRAPH_MODEL_DIR");
  EXPECT_EQ(builtin_model_dir().string(), before);
  EXPECT_THROW(load_builtin_model("stop"), std::invalid_argument);
}

TEST(BuiltinModel, TheOperatingCurveIsSpottingAgainAtEachPoint) {
  const auto model = load_builtin_model("sim");
  const auto test = held_out_sessions(2, 78);
  const auto quiet = quiet_sessions({"work", "box"}, 1, 78);
  const auto opts = skelgraph::gesture::sim_spotter_options();
  const auto curve = skelgraph::gesture::operating_curve(model, test, quiet, opts, {0.0, 0.5, 0.9}, {0.0, 0.5}, 2);
  ASSERT_EQ(curve.size(), 6u);
  EXPECT_EQ(curve[0].min_confidence, 0.0);
  EXPECT_EQ(curve[0].confirm, 0.0);
  EXPECT_EQ(curve[4].min_confidence, 0.5);
  EXPECT_EQ(curve[4].confirm, 0.5);
  // The first point is the options as given: the same as spotting once.
  std::vector<SpottingReport> reports;
  for (const auto& s : spot_sessions(model, test, opts)) reports.push_back(s.report);
  const auto r = combine(reports);
  EXPECT_EQ(curve[0].recall, r.recall);
  EXPECT_EQ(curve[0].precision, r.precision);
  EXPECT_EQ(curve[0].false_per_hour, skelgraph::gesture::spot_quiet(model, quiet, opts).per_hour("point"));
  EXPECT_GT(curve[0].recall, 0.5);
  // Here, asking for more confidence, or a confirmation, finds no more.
  for (std::size_t k = 0; k < curve.size(); ++k) {
    if (k % 3 != 0) {
      EXPECT_LE(curve[k].recall, curve[k - 1].recall) << k;
      EXPECT_LE(curve[k].false_per_hour, curve[k - 1].false_per_hour) << k;
    }
    if (k >= 3) {
      EXPECT_LE(curve[k].recall, curve[k - 3].recall) << k;
    }
  }
}
