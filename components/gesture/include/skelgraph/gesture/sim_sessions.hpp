#pragma once
// Simulated pointing sessions for training and measuring the spotter without
// outside data: the simulator's `point` scenario (pointing at the floor with
// either arm, between waves and stretches), its trackers fused offline with
// the Kalman method (what the live `gesture` component sees), and the true
// gestures from the scenario's phases with the true pointing targets. No DDS.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::gesture {

struct SimSession {
  std::string scenario = "point";
  std::vector<skeleton::Skeleton> fused;  // the fused skeletons (world frame), in time order
  std::vector<TruthGesture> truth;        // label point (with hold start and target), wave or stretch
  std::vector<std::pair<std::int64_t, std::int64_t>> rest;  // spans where the person stands at rest
  // Every frame of a pointing hold: the fused skeleton and the truth at that time, and the arm.
  struct Hold {
    skeleton::Skeleton fused, truth;
    bool right = false;
  };
  std::vector<Hold> holds;
};

// The spotter in the simulated cell: pointing lands on its floor within 4 m
// of the shoulder (max_target) and the trunk is upright (max_lean_m 0.07, in
// its level world frame); where the surfaces of a recording are and how its
// camera is tilted are not known, so `gesture spot` leaves both off.
SpotterOptions sim_spotter_options();

// The pointing arm's joint offsets (PointingCorrection::shoulder, hand): the
// median, per body axis, of where the fused shoulder and hand are against the
// true ones over the sessions' holds.
void learn_joint_offsets(const std::vector<SimSession>& sessions, PointingCorrection& c);

// A reference for the spotter's targets: for each true pointing hold, the
// fused shoulder and hand averaged over the whole hold as the truth times it
// (no spotter could know its bounds better), corrected by `c` as the spotter
// corrects them, and where that ray meets `floor` against the true target (m).
std::vector<double> whole_hold_target_errors(const std::vector<SimSession>& sessions, const PointingCorrection& c,
                                             const Surface& floor = {});

// One session of a scenario (the point scenario by default) with this seed
// (the scenario's people, the default two sensors). noise_scale scales the
// trackers' random errors (sim::SimConfig). Scenarios other than point have
// no true gestures: every event spotted in them is a false alarm.
SimSession simulate_session(std::uint64_t seed, const Surface& floor = {}, double noise_scale = 1.0,
                            const std::string& scenario = "point", double height_m = 1.75);

// The simulator's scenarios in which nobody gestures, what a worker does
// besides: walk, 360, hide, box, occ, sit, arms, and work (a bench beside a
// robot: reaching, picking and placing, carrying, turning to the robot,
// scratching the head, glasses, a tool from a shelf at the side).
const std::vector<std::string>& quiet_scenarios();

// `per_scenario` sessions of each scenario, seeds (seed + 1) * 1000 + 700 + i
// (none a training or test session of the point scenario has); for training,
// seed * 1000 + 300 + i (none of those either).
std::vector<SimSession> quiet_sessions(const std::vector<std::string>& scenarios, int per_scenario, std::uint64_t seed,
                                       const std::function<void(int done, int total)>& progress = {},
                                       double noise_scale = 1.0, bool training = false);

// False alarms: the events spotted in sessions where nobody gestures, per
// scenario and class, against the time the fused stream covered.
struct QuietReport {
  struct Scenario {
    std::string name;
    double seconds = 0;
    std::map<std::string, int> events;  // per class
    std::vector<SpottedEvent> spotted;  // every one of them
  };
  std::vector<Scenario> scenarios;      // in the order given, sessions of one scenario summed
  double hours = 0;
  std::map<std::string, int> events;    // per class, every scenario
  double per_hour(const std::string& label) const;
};
QuietReport spot_quiet(const Classifier& model, const std::vector<SimSession>& sessions, const SpotterOptions& options = sim_spotter_options());

// One operating point of pointing: spotting with these at spotting time.
struct OperatingPoint {
  double min_confidence = 0.0, confirm = 0.0;  // SpotterOptions'
  double recall = 0.0, precision = 0.0;        // on held-out pointing sessions
  double false_per_hour = 0.0;                 // pointing events per hour where nobody gestures
  double median_latency_hold_s = 0.0;          // from the hold's start to the event
};
// Pointing spotted again at every pair of (min_confidence, confirm), the rest
// of `options` kept: recall and precision on `test`, false pointing events per
// hour on `quiet`. In the order given, confirm outer; `threads` points at once.
std::vector<OperatingPoint> operating_curve(const Classifier& model, const std::vector<SimSession>& test,
                                            const std::vector<SimSession>& quiet, const SpotterOptions& options,
                                            const std::vector<double>& min_confidences = {0.0, 0.25, 0.5, 0.75, 0.9},
                                            const std::vector<double>& confirms = {0.0, 0.5}, int threads = 2);

// Labelled clips cut from sessions: each true gesture (action point, wave or
// stretch; from `pad` s before to `pad` s after) and one rest clip per rest
// span longer than 1 s (action rest). Subject: "sim<seed index>".
std::vector<Clip> session_clips(const std::vector<SimSession>& sessions, const ClassMap& map, FeatureSet set, double pad = 0.17);

// point vs everything else (garbage "other"), for sessions.
ClassMap sim_class_map();

// The classifier options for simulated sessions: thesis8 features, the
// right-handed canonical form, clips not trimmed (they are cut at the true
// gesture bounds; the spotter cuts its own segments).
ClassifierOptions sim_classifier_options();

// Sessions the training never sees (seeds (seed + 1) * 1000 + 500 + i).
// `height_m`: the people's height (the training sessions' is 1.75 m).
std::vector<SimSession> held_out_sessions(int sessions, std::uint64_t seed,
                                          const std::function<void(int done, int total)>& progress = {},
                                          double noise_scale = 1.0, double height_m = 1.75);

// Each session spotted (one Spotter per fused person) and scored against its own truth.
struct SessionSpotting {
  std::vector<SpottedEvent> events;
  SpottingReport report;
};
std::vector<SessionSpotting> spot_sessions(const Classifier& model, const std::vector<SimSession>& sessions,
                                           const SpotterOptions& options = sim_spotter_options());

// The default training: pointing sessions, and sessions of each quiet
// scenario whose false alarms it is trained again against (the best
// measured: docs/experiments/2026-12-04-quiet-gestures.md).
constexpr int kTrainSessions = 24;
constexpr int kTrainQuietSessions = 8;

// A classifier trained on `sessions` simulated sessions (seeds seed*1000 + i),
// and the clips it was trained on (count) for reports. With
// quiet_per_scenario > 0, what a first model spots in that many training
// sessions of each quiet scenario is added as "other" and it is trained again.
// The pointing correction is learnt by spotting the training sessions with `spot`.
// `heights_m`: the training people's heights, session i the (i mod n)-th
// (default: everyone 1.75 m, as the built-in model is trained).
Classifier train_on_sim(int sessions, std::uint64_t seed, const ClassifierOptions& options, std::size_t* clips = nullptr,
                        const std::function<void(int done, int total)>& progress = {}, const SpotterOptions& spot = sim_spotter_options(),
                        int quiet_per_scenario = kTrainQuietSessions, const std::vector<double>& heights_m = {1.75});

}  // namespace skelgraph::gesture
