// The gesture classifier: class maps (presets, YAML, errors with the line),
// left/right mirroring and the right-handed canonical form, the motion span,
// training and classifying synthetic classes, rejection of inputs in no
// class, metrics against hand-counted values, save/load, and leave-subject-out
// on the real Kinder-Gator recordings in ../shared/data.
#include <gtest/gtest.h>

#include <cmath>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/dataset.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/gesture/stream_spotting.hpp"

using namespace skelgraph::gesture;
namespace fs = std::filesystem;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = fs::temp_directory_path() / ("skelgraph_test_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// A synthetic 8-feature clip (thesis8 layout) of class k: the right arm's
// angles follow a class-specific path (0: up and hold, 1: out and back twice,
// 2: a slow sweep), with noise; `left` performs it with the left arm.
Sequence synthetic(int k, std::mt19937_64& rng, bool left = false) {
  std::normal_distribution<double> n(0, 0.05);
  std::uniform_int_distribution<int> len(50, 80);
  const int T = len(rng);
  Sequence x(T, 8);
  double prev_u = 3.0, prev_f = 3.0;
  for (int t = 0; t < T; ++t) {
    const double s = static_cast<double>(t) / (T - 1);
    double u = 3.0, f = 3.0;
    if (k == 0) u = f = 3.0 - 1.5 * std::min(1.0, 3 * s);
    if (k == 1) u = f = 3.0 - 1.2 * std::abs(std::sin(2 * M_PI * s));
    if (k == 2) { u = 3.0 - 0.8 * s; f = 3.0 - 2.0 * s; }
    u += n(rng);
    f += n(rng);
    const int r = left ? 0 : 2, o = left ? 2 : 0;
    x(t, r) = u;
    x(t, r + 1) = f;
    x(t, o) = 3.0 + n(rng);
    x(t, o + 1) = 3.0 + n(rng);
    x(t, 4 + r) = std::abs(u - prev_u) * 30;
    x(t, 4 + r + 1) = std::abs(f - prev_f) * 30;
    x(t, 4 + o) = std::abs(n(rng)) * 30;
    x(t, 4 + o + 1) = std::abs(n(rng)) * 30;
    prev_u = u;
    prev_f = f;
  }
  return x;
}

ClassMap three_classes() {
  ClassMap m;
  m.classes = {"raise", "wave", "sweep"};
  m.action_class = {{"raise", "raise"}, {"wave", "wave"}, {"sweep", "sweep"}};
  return m;
}

std::vector<Clip> synthetic_clips(int per_class, std::uint64_t seed, bool with_left = true) {
  std::mt19937_64 rng(seed);
  const char* names[3] = {"raise", "wave", "sweep"};
  std::vector<Clip> clips;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < per_class; ++i) {
      Clip c;
      c.action = names[k];
      c.label = k;
      c.subject = "s" + std::to_string(i % 5);
      c.source = c.action + std::to_string(i);
      c.x = synthetic(k, rng, with_left && i % 3 == 0);
      clips.push_back(std::move(c));
    }
  return clips;
}

ClassifierOptions small_options() {
  ClassifierOptions o;
  o.hmm.states = 4;
  o.hmm.covariance = Covariance::Diagonal;
  o.hmm.max_iterations = 30;
  o.features.set = FeatureSet::Thesis8;
  o.calibration_folds = 0;
  return o;
}

}  // namespace

TEST(ClassMap, PresetsFollowTheIssue) {
  const auto two = ClassMap::preset("two-class");
  EXPECT_EQ(two.classes, (std::vector<std::string>{"point", "other"}));
  EXPECT_EQ(two.label_of("Point-at-the-camera"), 0);
  EXPECT_EQ(two.label_of("Signal-someone-to-stop"), 1);  // garbage takes every other action
  const auto five = ClassMap::preset("five-class");
  EXPECT_EQ(five.classes.size(), 5u);
  EXPECT_EQ(five.label_of("Walk-in-place"), 2);
  EXPECT_EQ(five.label_of("Punch"), std::nullopt);  // in no class
  EXPECT_EQ(five.garbage_index(), -1);
  EXPECT_NE(error_of([] { ClassMap::preset("three-class"); }).find("unknown class preset"), std::string::npos);
}

TEST(ClassMap, LoadsYamlAndNamesTheLineOfAnError) {
  const auto good = write_temp("classes.yaml", "classes:\n  point: [Point-at-the-camera]\n  stop: [Signal-someone-to-stop, Punch]\ngarbage: rest\n");
  const auto m = ClassMap::load(good);
  EXPECT_EQ(m.classes, (std::vector<std::string>{"point", "stop", "rest"}));
  EXPECT_EQ(m.label_of("Punch"), 1);
  EXPECT_EQ(m.label_of("Walk-in-place"), 2);
  const auto twice = write_temp("twice.yaml", "classes:\n  a: [X]\n  b: [Y,\n      X]\n");
  const auto e = error_of([&] { ClassMap::load(twice); });
  EXPECT_NE(e.find(twice + ":4"), std::string::npos) << e;
  EXPECT_NE(e.find("in two classes"), std::string::npos) << e;
  const auto unknown = write_temp("unknown.yaml", "classes:\n  a: [X]\ngarbag: rest\n");
  EXPECT_NE(error_of([&] { ClassMap::load(unknown); }).find(unknown + ":3: unknown key 'garbag'"), std::string::npos);
  const auto empty = write_temp("empty.yaml", "classes:\n  a: []\n");
  EXPECT_NE(error_of([&] { ClassMap::load(empty); }).find("non-empty list"), std::string::npos);
  EXPECT_NE(error_of([] { ClassMap::load("/nonexistent/classes.yaml"); }).find("/nonexistent/classes.yaml"), std::string::npos);
  for (const auto& p : {good, twice, unknown, empty}) fs::remove(p);
}

TEST(Mirror, SwapsLeftAndRightAndTwiceIsTheIdentity) {
  for (auto set : {FeatureSet::Thesis8, FeatureSet::Extended, FeatureSet::Body}) {
    const auto names = feature_names(set);
    const auto perm = mirror_permutation(set);
    ASSERT_EQ(perm.size(), names.size());
    for (std::size_t i = 0; i < perm.size(); ++i) {
      ASSERT_GE(perm[i], 0);
      ASSERT_LT(perm[i], static_cast<int>(names.size())) << names[i] << " has no mirror image";
      EXPECT_EQ(perm[static_cast<std::size_t>(perm[i])], static_cast<int>(i));
      EXPECT_NE(perm[i], static_cast<int>(i)) << names[i];  // every feature here belongs to one side
    }
  }
  std::mt19937_64 rng(3);
  const Sequence left = synthetic(0, rng, true);
  bool was = false;
  const Sequence r = right_handed(left, FeatureSet::Thesis8, &was);
  EXPECT_TRUE(was);
  EXPECT_EQ(r.col(2), left.col(0));  // the left arm's motion is now on the right
  const Sequence again = right_handed(r, FeatureSet::Thesis8, &was);
  EXPECT_FALSE(was);
  EXPECT_EQ(again, r);
}

TEST(MotionSpan, FindsWhereTheArmsMove) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, 0.01);
  Sequence x = Sequence::Constant(100, 8, 3.0);
  for (int t = 0; t < 100; ++t)
    for (int i = 0; i < 8; ++i) x(t, i) += n(rng);
  for (int t = 40; t < 60; ++t) x(t, 3) = 1.5;  // the right forearm up between frames 40 and 59
  const auto s = motion_span(x, FeatureSet::Thesis8, 0.2, 5, 5);
  EXPECT_EQ(s.begin, 35);
  EXPECT_EQ(s.end, 65);
  const auto still = motion_span(Sequence::Constant(30, 8, 1.0), FeatureSet::Thesis8);
  EXPECT_EQ(still.begin, 0);
  EXPECT_EQ(still.end, 30);
}

TEST(Classifier, SeparatesSyntheticClassesPerformedWithEitherHand) {
  const auto map = three_classes();
  const auto train = synthetic_clips(12, 1);
  const auto test = synthetic_clips(6, 2);
  const auto model = Classifier::train(train, map, small_options());
  int correct = 0;
  for (const auto& c : test) correct += model.classify(c.x).label == c.label;
  EXPECT_GE(correct, 17) << "of 18";
  // Without the canonical form and without augmentation, a model trained on right hands only misses left ones.
  auto as_is = small_options();
  as_is.hands = Hands::AsIs;
  const auto right_only = Classifier::train(synthetic_clips(12, 1, false), map, as_is);
  int left_correct = 0, left_total = 0;
  for (const auto& c : test)
    if (c.x.col(0).mean() < 2.9 || c.x.col(1).mean() < 2.9) {  // performed with the left arm
      ++left_total;
      left_correct += right_only.classify(c.x).label == c.label;
    }
  ASSERT_GT(left_total, 0);
  EXPECT_LT(left_correct, left_total);
}

TEST(Classifier, CrossValidationAndRejection) {
  const auto map = three_classes();
  auto clips = synthetic_clips(10, 7);
  // Inputs in no class: both arms held straight up, a pose no class passes through.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0, 0.05);
  for (int i = 0; i < 10; ++i) {
    Clip c;
    c.action = "idle";
    c.subject = "s" + std::to_string(i % 5);
    c.x = Sequence::Constant(60, 8, 0.2);
    for (Eigen::Index t = 0; t < c.x.rows(); ++t)
      for (int j = 0; j < 8; ++j) c.x(t, j) = j < 4 ? 0.2 + n(rng) : std::abs(n(rng)) * 30;
    clips.push_back(std::move(c));
  }
  for (auto split : {Split::KFold, Split::LeaveSubjectOut}) {
    CvOptions cv;
    cv.split = split;
    int calls = 0;
    const auto results = cross_validate(clips, map, small_options(), cv, [&](int done, int total) {
      ++calls;
      EXPECT_LE(done, total);
    });
    EXPECT_EQ(calls, 5);
    ASSERT_EQ(results.size(), clips.size());
    for (std::size_t i = 0; i < results.size(); ++i) EXPECT_EQ(results[i].clip, i);
    const auto m = evaluate(results, map.classes);
    EXPECT_GE(m.accuracy, 0.9);
    EXPECT_EQ(m.unlabelled, 10);
    EXPECT_GE(m.unlabelled_rejected, 8);  // they score far below any gesture model's own clips
    EXPECT_GT(m.rejection_auc, 0.9);
  }
}

// Two classes that differ only in order: the right arm goes A then B, or B then A.
// One state sees the same frames in both; two states see the order.
TEST(Classifier, NestedCrossValidationChoosesInsideEachFold) {
  ClassMap map;
  map.classes = {"ab", "ba"};
  map.action_class = {{"ab", "ab"}, {"ba", "ba"}};
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, 0.05);
  std::vector<Clip> clips;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 10; ++i) {
      Clip c;
      c.action = map.classes[static_cast<std::size_t>(k)];
      c.label = k;
      c.subject = "s" + std::to_string(i % 5);
      c.x = Sequence(60, 8);
      for (Eigen::Index t = 0; t < 60; ++t) {
        const bool first = (t < 30) == (k == 0);
        for (int j = 0; j < 8; ++j) c.x(t, j) = n(rng);
        c.x(t, 2) += first ? 1.0 : 2.0;
        c.x(t, 3) += first ? 2.0 : 1.0;
      }
      clips.push_back(std::move(c));
    }
  std::vector<ClassifierOptions> configs(2, small_options());
  for (auto& c : configs) c.hands = Hands::AsIs;
  configs[0].hmm.states = 1;
  configs[1].hmm.states = 2;
  CvOptions cv;  // leave-subject-out: 5 outer folds, 4 inner
  const auto one_state = evaluate(cross_validate(clips, map, configs[0], cv), map.classes);
  EXPECT_LE(one_state.accuracy, 0.75);
  int calls = 0;
  const auto nested = nested_cross_validate(clips, map, configs, cv, [&](int, int total) {
    ++calls;
    EXPECT_EQ(total, 5);
  });
  EXPECT_EQ(calls, 5);
  ASSERT_EQ(nested.results.size(), clips.size());
  EXPECT_EQ(nested.chosen, std::vector<int>(5, 1));
  EXPECT_GE(evaluate(nested.results, map.classes).accuracy, 0.95);
  EXPECT_THROW(nested_cross_validate(clips, map, {}, cv), ModelError);
}

TEST(Classifier, HandFeaturesNeedWristsAndStayOffline) {
  skelgraph::playback::Recording rec;
  rec.format = "generic";
  rec.source = "walk.csv";
  rec.frames.resize(3);
  FeatureOptions f;
  f.set = FeatureSet::Hands;
  const auto e = error_of([&] { recording_features(rec, f); });
  EXPECT_NE(e.find("walk.csv: the 'hands' features need wrist joints; this generic recording has none"), std::string::npos) << e;
  rec.extra_joints["left_wrist"].assign(3, Eigen::Vector3d::Zero());
  rec.extra_joints["right_wrist"].assign(3, Eigen::Vector3d::Zero());
  EXPECT_EQ(recording_features(rec, f).x.cols(), 16);
  // A model on hand features spots only where wrists come with the skeletons (recordings, offline).
  auto o = small_options();
  o.features.set = FeatureSet::Hands;
  o.hands = Hands::AsIs;
  std::vector<Clip> clips = synthetic_clips(4, 3, false);
  for (auto& c : clips) {
    Sequence x = Sequence::Random(c.x.rows(), 16);
    x.leftCols(4) = c.x.leftCols(4);
    c.x = x;
  }
  const auto model = Classifier::train(clips, three_classes(), o);
  Spotter spotter(model, {});
  skelgraph::skeleton::Skeleton frame;
  const auto why = error_of([&] { spotter.step(frame); });
  EXPECT_NE(why.find("need wrist joints; this skeleton stream carries none"), std::string::npos) << why;
  const Wrists w;
  EXPECT_EQ(error_of([&] { spotter.step(frame, &w); }), "");
  // The 'arm' features model the active arm only: the clip must be made right-handed first.
  o.features.set = FeatureSet::Arm;
  for (const auto hands : {Hands::AsIs, Hands::Augment}) {
    o.hands = hands;
    EXPECT_NE(error_of([&] { Classifier::train(clips, three_classes(), o); }).find("needs --hands canonical"), std::string::npos);
  }
  o.hands = Hands::Canonical;
  const auto arm = Classifier::train(clips, three_classes(), o);
  EXPECT_EQ(arm.models().front().dim(), 8);  // the right arm's 5 values and 3 speeds
  EXPECT_EQ(arm.classify(clips.front().x).scores.size(), 3u);
  // Saved and loaded, it classifies the same; a file claiming other hands is refused.
  auto j = arm.to_json();
  EXPECT_EQ(Classifier::from_json(j).classify(clips.front().x).scores, arm.classify(clips.front().x).scores);
  j["hands"] = "as-is";
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("'arm' models need 'hands': \"canonical\""), std::string::npos);
}

TEST(Metrics, MatchHandCountedValues) {
  // Truth/prediction pairs: (0,0) (0,1) (1,1) (1,1) (1,0), and one clip in no class.
  const auto r = [](int truth, int label, double s0, double s1, bool rejected) {
    ClipResult c;
    c.truth = truth;
    c.decision.label = label;
    c.decision.scores = {s0, s1};
    c.decision.rejected = rejected;
    return c;
  };
  const std::vector<ClipResult> results{r(0, 0, 5, 1, false), r(0, 1, 1, 2, false), r(1, 1, 0, 4, false),
                                        r(1, 1, 1, 3, true),  r(1, 0, 3, 2, false), r(-1, 0, -9, -10, true)};
  const auto m = evaluate(results, {"point", "other"});
  EXPECT_EQ(m.confusion, (std::vector<std::vector<int>>{{1, 1}, {1, 2}}));
  EXPECT_DOUBLE_EQ(m.accuracy, 3.0 / 5);
  EXPECT_DOUBLE_EQ(m.precision[0], 0.5);
  EXPECT_DOUBLE_EQ(m.recall[1], 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.f1[0], 0.5);
  EXPECT_EQ(m.rejected_labelled, 1);
  EXPECT_EQ(m.unlabelled_rejected, 1);
  EXPECT_DOUBLE_EQ(m.accuracy_with_rejection, 3.0 / 6);  // (0,0), (1,1) accepted, and the rejected unlabelled one
  // Detection of "point" by s0 - s1: positives 4, -1; negatives -4, -2, 1 (and the unlabelled 1):
  // positive 4 beats all 4 negatives; -1 beats -4 and -2: AUC = 6 / 8.
  EXPECT_DOUBLE_EQ(m.detection_auc, 6.0 / 8);
  const auto j = to_json(m);
  EXPECT_EQ(j["per_class"]["point"]["f1"], 0.5);
  EXPECT_NE(confusion_svg(m, "t").find("<svg"), std::string::npos);
  EXPECT_NE(confusion_text(m).find("precision"), std::string::npos);
}

TEST(Classifier, SavesAndLoadsAndRefusesMalformedFiles) {
  auto model = Classifier::train(synthetic_clips(8, 3), three_classes(), small_options());
  model.set_pointing_correction({3.5, -1.25, Eigen::Vector3d(0.02, 0.03, 0.01), Eigen::Vector3d(0.0, 0.06, 0.07)});
  const auto path = write_temp("model.json", "");
  model.save(path);
  const auto back = Classifier::load(path);
  EXPECT_EQ(back.labels(), model.labels());
  EXPECT_EQ(back.threshold(), model.threshold());
  EXPECT_EQ(back.hands(), model.hands());
  EXPECT_EQ(back.pointing_correction().elevation, 3.5);
  EXPECT_EQ(back.pointing_correction().azimuth_out, -1.25);
  EXPECT_EQ(back.pointing_correction().shoulder, Eigen::Vector3d(0.02, 0.03, 0.01));
  EXPECT_EQ(back.pointing_correction().hand, Eigen::Vector3d(0.0, 0.06, 0.07));
  std::mt19937_64 rng(9);
  for (int k = 0; k < 3; ++k) {
    const auto x = synthetic(k, rng);
    const auto a = model.classify(x), b = back.classify(x);
    EXPECT_EQ(a.label, b.label);
    for (std::size_t i = 0; i < a.scores.size(); ++i) EXPECT_NEAR(a.scores[i], b.scores[i], 1e-9 * std::abs(a.scores[i]));
  }
  auto j = model.to_json();
  j["models"][0]["class"] = 7;
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("models[0]: 'class' 7 is not a label index"), std::string::npos);
  j = model.to_json();
  j.erase("hands");
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("missing field 'hands'"), std::string::npos);
  j = model.to_json();
  j["pointing_correction"] = {{"elevation_deg", "up"}};
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("'pointing_correction' must be"), std::string::npos);
  j = model.to_json();
  j["pointing_correction"]["hand_offset_m"] = {0.0, 0.06};
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("'pointing_correction.hand_offset_m' must be [out, up, forward]"),
            std::string::npos);
  j = model.to_json();
  j["pointing_correction"].erase("shoulder_offset_m");  // a model from before the joint offsets: none
  j["pointing_correction"].erase("hand_offset_m");
  EXPECT_EQ(Classifier::from_json(j).pointing_correction().hand, Eigen::Vector3d::Zero());
  // The operating point travels with the model; a model without one cuts nowhere.
  model.set_operating_point({0.4, 0.5});
  j = model.to_json();
  EXPECT_EQ(Classifier::from_json(j).operating_point().min_confidence, 0.4);
  EXPECT_EQ(Classifier::from_json(j).operating_point().confirm_s, 0.5);
  j["operating_point"]["min_confidence"] = 1.5;
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("'operating_point.min_confidence' must be a number from 0 to 1"),
            std::string::npos);
  j["operating_point"] = {{"min_confidence", 0.2}};
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("'operating_point.confirm_s' must be a number from 0 to 10"),
            std::string::npos);
  j.erase("operating_point");
  EXPECT_EQ(Classifier::from_json(j).operating_point().min_confidence, 0.0);
  EXPECT_EQ(Classifier::from_json(j).operating_point().confirm_s, 0.0);
  j = model.to_json();
  j["version"] = 2;
  EXPECT_NE(error_of([&] { Classifier::from_json(j); }).find("unsupported 'version'"), std::string::npos);
  std::ofstream(path) << "{ not json";
  EXPECT_NE(error_of([&] { Classifier::load(path); }).find(path + ": not JSON"), std::string::npos);
  fs::remove(path);
}

// ---- the real recordings (never copied into the project) ----

namespace {
std::string kinder_gator() {
  if (const char* d = std::getenv("SKELGRAPH_DATA_DIR")) return std::string(d) + "/kinder-gator/adults";
  const char* src = std::getenv("SKELGRAPH_SOURCE_DIR");
  return std::string(src ? src : ".") + "/../shared/data/kinder-gator/adults";
}

// Leave-subject-out two-class on the Kinder-Gator adults (160 clips, 10 subjects).
Metrics kinder_gator_two_class(FeatureSet set, const std::function<void(ClassifierOptions&)>& tune = {}) {
  const auto dir = kinder_gator();
  if (!fs::is_directory(dir)) throw std::runtime_error(dir + " is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)");
  const auto map = ClassMap::preset("two-class");
  DatasetOptions d;
  d.features.set = set;
  const auto clips = load_clips({dir}, map, d);
  EXPECT_EQ(clips.size(), 160u);
  std::set<std::string> subjects;
  for (const auto& c : clips) subjects.insert(c.subject);
  EXPECT_EQ(subjects.size(), 10u);
  auto o = ClassifierOptions{};
  o.features = d.features;
  o.calibration_folds = 0;
  if (tune) tune(o);
  return evaluate(cross_validate(clips, map, o, {}), map.classes);
}
}  // namespace

TEST(KinderGator, LeaveSubjectOutTwoClass) {
  const auto m = kinder_gator_two_class(FeatureSet::Thesis8);
  // Every clip is scored once; the off-the-shelf baseline (pomegranate, the same features) reaches about 94 %.
  int n = 0;
  for (const auto& row : m.confusion)
    for (int v : row) n += v;
  EXPECT_EQ(n, 160);
  EXPECT_GE(m.accuracy, 0.93);
  EXPECT_GE(m.recall[0], 0.6);
}

// With the hand segment (Kinect v1's wrist and hand), pointing is told apart
// from signal-to-stop and push-a-button. The configuration is what `gesture
// train` and `cv` take with no model option (hands, 3 states, 2 mixtures,
// diagonal: the winner of `gesture cv --features hands --sweep --sweep-mixtures 1 2`).
TEST(KinderGator, LeaveSubjectOutTwoClassWithHands) {
  DatasetOptions d;
  d.format = skelgraph::playback::Format::KinderGator;
  ASSERT_TRUE(inputs_have_wrists({kinder_gator()}, d));
  const auto best = best_configuration("two-class", true);
  ASSERT_EQ(best.features, FeatureSet::Hands);
  const auto m = kinder_gator_two_class(best.features, [&](ClassifierOptions& o) { best.apply(o); });
  EXPECT_GE(m.accuracy, 0.98);
  EXPECT_GE(m.f1[0], 0.9);
}

// Without wrists the default falls back to what runs on 15 joints: the same
// Kinder-Gator file written as a generic CSV without its extra joints.
TEST(KinderGator, TheDefaultConfigurationNeedsWristsOnlyWhereTheInputsHaveThem) {
  namespace pb = skelgraph::playback;
  fs::path file;
  for (const auto& e : fs::directory_iterator(kinder_gator()))
    if (e.path().extension() == ".csv") { file = e.path(); break; }
  ASSERT_FALSE(file.empty()) << kinder_gator() << " has no clips: tests read ../shared/data (or SKELGRAPH_DATA_DIR)";
  auto rec = pb::read_recording(pb::Format::KinderGator, file.string());
  ASSERT_FALSE(rec.extra_joints.empty());
  const auto csv = [](const pb::Recording& r) {
    std::ostringstream os;
    pb::write_generic_csv(r, os);
    return os.str();
  };
  const auto with = write_temp("with_wrists.csv", csv(rec));
  rec.extra_joints.clear();
  const auto without = write_temp("without_wrists.csv", csv(rec));
  const auto empty = write_temp("empty.csv", "");
  DatasetOptions d;
  d.format = pb::Format::Generic;
  EXPECT_TRUE(inputs_have_wrists({with}, d));
  EXPECT_FALSE(inputs_have_wrists({without}, d));
  EXPECT_TRUE(inputs_have_wrists({empty, with}, d));  // a file that does not read does not decide
  EXPECT_FALSE(inputs_have_wrists({empty, fs::path(empty).replace_extension("missing.csv").string()}, d));
  for (const auto& f : {with, without, empty}) fs::remove(f);
  for (const char* set : {"two-class", "five-class", "robot"}) {
    EXPECT_FALSE(needs_wrists(best_configuration(set, false).features)) << set;
    EXPECT_TRUE(needs_wrists(best_configuration(set, true).features)) << set;
  }
  const auto five = best_configuration("five-class", true);
  EXPECT_EQ(five.features, FeatureSet::Arm);
  EXPECT_EQ(five.init, Init::KMeans);
}

// Annotated streams: two gestures, each a bump of its own feature that peaks
// at the action point, over noise; leave-subject-out spotting finds them near
// the points, and nothing where no gesture is.
namespace {
AnnotatedStream synthetic_stream(const std::string& subject, std::uint64_t seed) {
  AnnotatedStream s;
  s.source = subject + ".csv";
  s.subject = subject;
  const int frames = 30 * 60;  // a minute at 30 Hz
  s.x = Sequence::Zero(frames, 3);
  std::uint64_t state = seed;
  const auto noise = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 53) - 0.5;
  };
  for (int t = 0; t < frames; ++t) {
    s.stamps.push_back(static_cast<std::int64_t>(t) * 33'333'333);
    for (int d = 0; d < 3; ++d) s.x(t, d) = 0.1 * noise();
  }
  for (int k = 0; k < 12; ++k) {
    const int peak = 60 + k * 140;  // every 4.7 s, alternating A and B
    const int dim = k % 2;
    for (int t = peak - 20; t <= peak; ++t) s.x(t, dim) += 1.0 - static_cast<double>(peak - t) / 20.0;
    s.annotations.push_back({dim == 0 ? "A" : "B", s.stamps[static_cast<std::size_t>(peak)], s.stamps[static_cast<std::size_t>(peak)]});
  }
  return s;
}
}  // namespace

// Near misses: garbage windows that end at the given offsets from each
// action point, unless another action point is within 0.3 s of that end.
TEST(StreamSpotting, NearMissesAreGarbageUnlessAnotherGestureIsThere) {
  auto s = synthetic_stream("s0", 11);
  const auto map = stream_class_map({s});
  const auto garbage = [&](const StreamSpotOptions& o) {
    int n = 0;
    for (const auto& w : stream_windows(s, map, o)) n += w.action == "none" ? 1 : 0;
    return n;
  };
  StreamSpotOptions without, with;
  without.near_negative_offsets_s.clear();
  with.near_negative_offsets_s = {-0.7, -0.5, 0.5, 0.7};
  EXPECT_EQ(garbage(with) - garbage(without), 12 * 4);
  // A second "A" 0.5 s after the first: the first's +0.5 and +0.7 and the second's -0.5 and -0.7 fall within 0.3 s
  // of the other one and are not garbage; the second's +0.5 and +0.7 are (the third is 4.2 s on). The plain garbage
  // windows stay at least 0.8 s from both.
  s.annotations.insert(s.annotations.begin() + 1, {"A", s.annotations[0].end_ns + 500'000'000, s.annotations[0].end_ns + 500'000'000});
  EXPECT_EQ(garbage(with) - garbage(without), 11 * 4 + 2 + 2);  // the other 11, the first's two before, the second's two after
}

TEST(StreamSpotting, NearMissOffsetsFromText) {
  EXPECT_EQ(parse_near_misses("-0.7,-0.5,0.5,0.7"), (std::vector<double>{-0.7, -0.5, 0.5, 0.7}));
  EXPECT_TRUE(parse_near_misses("none").empty());
  EXPECT_EQ(error_of([] { parse_near_misses("0.5,x"); }), "'x' is not a number of seconds in [-5, 5]");
  EXPECT_EQ(error_of([] { parse_near_misses("0.5s"); }), "'0.5s' is not a number of seconds in [-5, 5]");
  EXPECT_EQ(error_of([] { parse_near_misses("6"); }), "'6' is not a number of seconds in [-5, 5]");
  EXPECT_EQ(error_of([] { parse_near_misses("0.5,,0.7"); }), "'' is not a number of seconds in [-5, 5]");
}

TEST(StreamSpotting, FindsEachGestureNearItsActionPoint) {
  std::vector<AnnotatedStream> streams;
  for (int subject = 0; subject < 3; ++subject) streams.push_back(synthetic_stream("s" + std::to_string(subject), 11 + subject));
  const auto map = stream_class_map(streams);
  ASSERT_EQ(map.classes, (std::vector<std::string>{"A", "B", "none"}));
  StreamSpotOptions o;
  const auto windows = stream_windows(streams[0], map, o);
  int positives = 0;
  for (const auto& w : windows) positives += w.action != "none" ? 1 : 0;
  EXPECT_EQ(positives, 12 * 4);  // every action point, every offset
  EXPECT_GT(windows.size(), 100u);
  const auto r = cross_validate_streams(streams, ClassifierOptions{}, o);
  EXPECT_EQ(r.streams, 3u);
  ASSERT_EQ(r.per_class.size(), 2u);
  for (const auto& k : r.per_class) {
    EXPECT_EQ(k.truth, 18) << k.label;
    EXPECT_GE(k.recall, 0.9) << k.label;
    EXPECT_GE(k.precision, 0.9) << k.label;
  }
  EXPECT_GE(r.macro_f1, 0.9);
  EXPECT_LT(std::abs(r.median_latency_s), o.slack_s);
  // Trained on all, saved and loaded: the same events.
  ClassifierOptions knn_options;
  knn_options.features.set = FeatureSet::Body;
  const auto spotter = StreamSpotter::train(streams, knn_options, o);
  const auto path = ::testing::TempDir() + "/stream_spotter.json";
  spotter.save(path);
  ASSERT_TRUE(StreamSpotter::is_stream_spotter(path));
  const auto loaded = StreamSpotter::load(path);
  EXPECT_EQ(loaded.classes(), (std::vector<std::string>{"A", "B"}));
  EXPECT_EQ(loaded.feature_set(), FeatureSet::Body);
  const auto before = spotter.spot(streams[1]), after = loaded.spot(streams[1]);
  ASSERT_EQ(before.size(), after.size());
  ASSERT_GE(before.size(), 10u);
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(before[i].label, after[i].label);
    EXPECT_EQ(before[i].end_ns, after[i].end_ns);
  }
  // Recognised by its format whatever comes before it (keys are written sorted: "classes" first).
  std::ofstream(::testing::TempDir() + "/long_classes.json")
      << R"({"classes": [")" << std::string(500, 'x') << R"("], "format": "skelgraph-stream-spotter"})";
  EXPECT_TRUE(StreamSpotter::is_stream_spotter(::testing::TempDir() + "/long_classes.json"));
  EXPECT_FALSE(StreamSpotter::is_stream_spotter(::testing::TempDir() + "/nothing_here.json"));
  std::ofstream(::testing::TempDir() + "/not_spotter.json") << R"({"format": "skelgraph-stream-spotter", "version": 1})";
  EXPECT_THROW(StreamSpotter::load(::testing::TempDir() + "/not_spotter.json"), ModelError);
  // The same windows through the HMM classifier run end to end too.
  o.model = "hmm";
  ClassifierOptions c;
  c.trimmed = false;
  c.hands = Hands::AsIs;  // three made-up features: no arms to mirror
  c.hmm.states = 3;
  c.hmm.covariance = Covariance::Diagonal;
  const auto h = cross_validate_streams(streams, c, o);
  EXPECT_EQ(h.per_class.size(), 2u);
  EXPECT_EQ(h.per_class[0].truth + h.per_class[1].truth, 36);
}

// The nearest-neighbour experiment's distance: a clip played slower is near
// its original, another movement is not, nothing is infinitely far.
TEST(Nearest, DtwForgivesSpeedNotShape) {
  Sequence a(40, 2), slow(60, 2), other(40, 2);
  for (int i = 0; i < 40; ++i) a.row(i) << std::sin(i * 0.15), std::cos(i * 0.15);
  for (int i = 0; i < 60; ++i) slow.row(i) << std::sin(i * 0.1), std::cos(i * 0.1);
  for (int i = 0; i < 40; ++i) other.row(i) << std::cos(i * 0.3), 0.5;
  EXPECT_DOUBLE_EQ(dtw_distance(a, a, 0.2), 0.0);
  EXPECT_LT(dtw_distance(a, slow, 0.2), 0.02);
  EXPECT_GT(dtw_distance(a, other, 0.2), 10 * dtw_distance(a, slow, 0.2));
  EXPECT_TRUE(std::isinf(dtw_distance(a, Sequence(0, 2), 0.2)));
}

// The split by body size: the subjects with the shorter arms form one fold,
// those with the longer the other, every clip of a subject in its half.
TEST(CrossValidation, TheSizeSplitCutsTheSubjectsByArmLength) {
  auto clips = synthetic_clips(10, 7);  // subjects s0..s4
  const std::map<std::string, double> arm{{"s0", 0.62}, {"s1", 0.55}, {"s2", 0.66}, {"s3", 0.58}, {"s4", 0.60}};
  for (auto& c : clips) c.arm_length_m = arm.at(c.subject) + (c.label == 1 ? 0.01 : 0.0);
  CvOptions cv;
  cv.split = Split::BodySize;
  const auto results = cross_validate(clips, three_classes(), small_options(), cv);
  ASSERT_EQ(results.size(), clips.size());
  std::map<std::string, std::set<int>> folds;
  for (const auto& r : results) folds[clips[r.clip].subject].insert(r.fold);
  for (const auto& [s, f] : folds) ASSERT_EQ(f.size(), 1u) << s;
  // The shorter half (of 5 subjects, the middle one goes with the shorter: s1 0.55, s3 0.58, s4 0.60) in fold 0.
  EXPECT_EQ(*folds["s1"].begin(), 0);
  EXPECT_EQ(*folds["s3"].begin(), 0);
  EXPECT_EQ(*folds["s4"].begin(), 0);
  EXPECT_EQ(*folds["s0"].begin(), 1);
  EXPECT_EQ(*folds["s2"].begin(), 1);
  // A subject never measured (no arm joints in any clip): a clear error.
  for (auto& c : clips)
    if (c.subject == "s2") c.arm_length_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(cross_validate(clips, three_classes(), small_options(), cv), ModelError);
}
