// The presence measure (eval::Presence): completeness against the truth per
// person, departures seen, instances against the people there, failed writes.
#include <gtest/gtest.h>

#include "skelgraph/eval/presence.hpp"

using namespace skelgraph;
using skeleton::JointId;

namespace {
constexpr std::int64_t kMs = 1'000'000;

skeleton::Skeleton at(const std::string& stream, std::uint32_t id, double x) {
  skeleton::Skeleton s;
  s.sensor_id = stream;
  s.person_id = id;
  for (auto& j : s.joints) {
    j.position = Eigen::Vector3d(x, 1.0, 0.0);
    j.confidence = 1.0f;
  }
  return s;
}
}  // namespace

TEST(Presence, CompletenessIsTheShareOfTheTrackedTimeTheFusedSkeletonShowsThePerson) {
  eval::Presence p;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, 0.0);
  p.pose("s1", pose);
  // 4 s: person 1 tracked all along, shown in the second half only; person 2
  // never tracked (walking in outside the views): not counted against fusion.
  for (int k = 0; k <= 40; ++k) {
    const std::int64_t t = 1000 * kMs + k * 100 * kMs;
    p.truth(at("truth", 1, 0.0), t);
    p.truth(at("truth", 2, 3.0), t);
    p.raw(at("s1", 7, 0.1), t);
    if (k >= 20) p.fused(at("fused", 5, -0.1), t);
    p.fused(at("fused", 6, 1.5), t);  // nobody's: shows no one
    p.sample(t);
  }
  const auto r = p.report(true);
  EXPECT_EQ(r["people"]["seen"], 2);
  EXPECT_EQ(r["people"]["never_tracked"], 1);
  EXPECT_EQ(r["people"]["never_shown"], 1);
  EXPECT_NEAR(r["completeness"]["tracked_s"].get<double>(), 4.0, 0.05);
  EXPECT_NEAR(r["completeness"]["shown_of_tracked"].get<double>(), 0.5, 0.05);
  EXPECT_NEAR(r["completeness"]["present_s"].get<double>(), 8.0, 0.1);
  EXPECT_EQ(r["completeness"]["people_scored"], 1);
  EXPECT_EQ(r["completeness"]["people_below_90_percent"], 1);
}

TEST(Presence, DeparturesAreTimedFromTheInputsAndFromTheTruth) {
  eval::Presence p;
  p.pose("s1", Eigen::Isometry3d::Identity());
  for (int k = 0; k < 10; ++k) {
    const std::int64_t t = k * 100 * kMs;
    p.truth(at("truth", 1, 0.0), t);
    p.truth(at("truth", 2, 2.0), t);
    p.raw(at("s1", 7, 0.0), t);
    p.raw(at("s1", 8, 2.0), t);
    p.fused(at("fused", 5, 0.0), t);
    p.fused(at("fused", 6, 2.0), t);
    p.sample(t);
  }
  // Person 1 walks away (the tracker's ghost stays where they were), leaves;
  // the tracker lets go later, and fusion 20 ms after that.
  for (int k = 10; k < 20; ++k) {
    const std::int64_t t = k * 100 * kMs;
    p.truth(at("truth", 1, 0.2 * (k - 9)), t);
    p.raw(at("s1", 7, 0.0), t);
    p.fused(at("fused", 5, 0.0), t);
  }
  p.truth_gone(1, 2000 * kMs);
  p.raw_gone("s1", 7, 2300 * kMs);
  p.fused_gone("fused", 5, 2320 * kMs);
  // Person 2 left too, but their fused skeleton is still there.
  p.truth_gone(2, 2000 * kMs);
  p.raw_gone("s1", 8, 2100 * kMs);
  const auto r = p.report();
  EXPECT_EQ(r["departures"]["people"], 2);
  EXPECT_EQ(r["departures"]["seen"], 1);
  EXPECT_EQ(r["departures"]["still_shown"], 1);
  EXPECT_EQ(r["departures"]["late"], 0);
  EXPECT_NEAR(r["departures"]["after_inputs_ms"]["max"].get<double>(), 20.0, 1e-6);
  EXPECT_NEAR(r["departures"]["after_truth_ms"]["max"].get<double>(), 320.0, 1e-6);
  EXPECT_EQ(r["fused"]["alive"], 1);
  EXPECT_EQ(r["raw"]["alive"], 0);
  EXPECT_EQ(p.people_left(), 2u);
  // A late one: 1.5 s after its inputs.
  p.truth(at("truth", 3, 5.0), 2500 * kMs);
  p.raw(at("s1", 9, 5.0), 2500 * kMs);
  p.fused(at("fused", 10, 5.0), 2500 * kMs);
  p.truth_gone(3, 2600 * kMs);
  p.raw_gone("s1", 9, 2600 * kMs);
  p.fused_gone("fused", 10, 4100 * kMs);
  EXPECT_EQ(p.report()["departures"]["late"], 1);
}

TEST(Presence, InstancesAreBoundedByThePeopleThereAndFailedWritesAdd) {
  eval::PresenceOptions o;
  o.linger_ns = 1000 * kMs;
  eval::Presence p(o);
  p.pose("s1", Eigen::Isometry3d::Identity());
  p.pose("s2", Eigen::Isometry3d::Identity());
  p.truth(at("truth", 1, 0.0), 0);
  p.truth(at("truth", 2, 2.0), 0);
  p.output("fusion", "skelgraph/skeleton/fused", 0, 2, 0);
  p.output("cell", "skelgraph/skeleton/raw", 0, 4, 0);   // 2 people x 2 sensors
  p.truth_gone(2, 100 * kMs);
  p.output("fusion", "skelgraph/skeleton/fused", 0, 2, 500 * kMs);  // within the linger: fine
  p.output("fusion", "skelgraph/skeleton/fused", 3, 3, 1500 * kMs);  // 1 person there, 3 instances
  p.output("cell", "skelgraph/calibration", 2, 2, 1500 * kMs);      // not people: not bounded
  const auto r = p.report();
  EXPECT_EQ(r["failed_writes"], 5);
  EXPECT_EQ(p.failed_writes(), 5u);
  for (const auto& out : r["outputs"]) {
    if (out["topic"] == "skelgraph/skeleton/fused") {
      EXPECT_EQ(out["max_instances_over_people"], 2);
      EXPECT_EQ(out["max_instances"], 3);
    }
    if (out["topic"] == "skelgraph/skeleton/raw") {
      EXPECT_EQ(out["max_instances_over_people"], 0);
    }
    if (out["topic"] == "skelgraph/calibration") {
      EXPECT_FALSE(out.contains("max_instances_over_people"));
    }
  }
}
