// The DDS layer on its own: typed and raw endpoints, discovery, QoS, the
// loopback profile. Runs inside tests/netns-lo.sh (a namespace with only lo).

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "../support/test_support.hpp"
#include "skelgraph/msg/message_table.hpp"
#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/discovery.hpp"
#include "skelgraph/runtime/pubsub.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;

TEST(RuntimeDds, TypedSkeletonRoundTripWithCounters) {
  Context a("writer_comp", test::test_config());
  Context b("reader_comp", test::test_config());
  test::Collector<msg::Skeleton> got;
  Subscription<msg::Skeleton> sub(b, topics::kSkeletonTruth,
                                  [&](const msg::Skeleton& s, const SampleMeta&) { got.add(s); });
  Publisher<msg::Skeleton> pub(a, topics::kSkeletonTruth);
  b.executor().start();
  ASSERT_TRUE(pub.wait_for_matched(1, 10s));
  ASSERT_TRUE(sub.wait_for_matched(1, 10s));
  for (std::uint32_t i = 0; i < 20; ++i) {
    msg::Skeleton s;
    s.sensor_id("truth");
    s.person_id(i % 2);
    s.frame_number(i);
    s.joints()[msg::JOINT_TORSO].position().y(1.0 + i);
    ASSERT_TRUE(pub.publish(s));
  }
  ASSERT_TRUE(got.wait_count(20));
  // Reliable: all 20, none twice, and in order within each instance (person).
  std::vector<std::uint64_t> frames[2];
  for (const auto& s : got.items()) {
    frames[s.person_id()].push_back(s.frame_number());
    EXPECT_DOUBLE_EQ(s.joints()[msg::JOINT_TORSO].position().y(), 1.0 + static_cast<double>(s.frame_number()));
  }
  EXPECT_EQ(frames[0], (std::vector<std::uint64_t>{0, 2, 4, 6, 8, 10, 12, 14, 16, 18}));
  EXPECT_EQ(frames[1], (std::vector<std::uint64_t>{1, 3, 5, 7, 9, 11, 13, 15, 17, 19}));
  ASSERT_TRUE(b.executor().run_sync([] {}, 5s));
  std::uint64_t in = 0, out = 0;
  for (const auto& c : a.counters()) out += c->is_output ? c->count.load() : 0;
  for (const auto& c : b.counters()) in += c->is_output ? 0 : c->count.load();
  EXPECT_EQ(out, 20u);
  EXPECT_EQ(in, 20u);
}

TEST(RuntimeDds, RawSubscriptionGetsCdrThatDecodes) {
  Context a("sync_writer", test::test_config());
  Context b("raw_reader", test::test_config());
  test::Collector<std::vector<std::uint8_t>> got;
  RawSubscription sub(b, topics::kSync.name, "skelgraph::msg::SyncCommand", false, topics::kSync.qos,
                      [&](const msg::RawSample& s, const SampleMeta&) { got.add(s.payload); });
  Publisher<msg::SyncCommand> pub(a, topics::kSync);
  b.executor().start();
  ASSERT_TRUE(pub.wait_for_matched(1, 10s));
  msg::SyncCommand c;
  c.kind(msg::SYNC_START);
  c.label("raw");
  c.session_id(77);
  ASSERT_TRUE(pub.publish(c));
  ASSERT_TRUE(got.wait_count(1));
  const auto j = msg::find_message("skelgraph::msg::SyncCommand")->decode(got.items()[0]);
  EXPECT_EQ(j["kind"], "START");
  EXPECT_EQ(j["label"], "raw");
  EXPECT_EQ(j["session_id"], 77);
}

TEST(RuntimeDds, RawSubscriptionMatchesKeyedTopic) {
  Context a("skel_writer", test::test_config());
  Context b("raw_skel_reader", test::test_config());
  test::Collector<std::vector<std::uint8_t>> got;
  RawSubscription sub(b, topics::kSkeletonRaw.name, "skelgraph::msg::Skeleton", true,
                      {Reliability::BestEffort, Durability::Volatile, 100},
                      [&](const msg::RawSample& s, const SampleMeta&) { got.add(s.payload); });
  Publisher<msg::Skeleton> pub(a, topics::kSkeletonRaw);
  b.executor().start();
  ASSERT_TRUE(pub.wait_for_matched(1, 10s));
  msg::Skeleton s;
  s.sensor_id("k2");
  s.person_id(5);
  // Best effort: a sample sent before the reader's side matched may be lost, so
  // publish again until one arrives (bounded).
  bool arrived = false;
  for (int i = 0; i < 100 && !arrived; ++i) {
    pub.publish(s);
    arrived = got.wait_count(1, 100ms);
  }
  ASSERT_TRUE(arrived);
  EXPECT_EQ(msg::find_message("skelgraph::msg::Skeleton")->decode(got.items()[0])["person_id"], 5);
}

TEST(RuntimeDds, DiscoverySeesTopicsTypesAndComponentNames) {
  DiscoveryObserver observer;
  Context tool("observer", test::test_config(), &observer);
  Context comp("my_component", test::test_config());
  Publisher<msg::GestureEvent> pub(comp, topics::kGestureEvent);
  EndpointInfo w;
  ASSERT_TRUE(observer.wait_for_writer(topics::kGestureEvent.name, 10s, &w));
  EXPECT_EQ(w.type_name, "skelgraph::msg::GestureEvent");
  EXPECT_EQ(w.reliability, Reliability::Reliable);
  EXPECT_FALSE(w.keyed);
  // The participant name may arrive a moment after the endpoint.
  bool named = false;
  for (int i = 0; i < 100 && !named; ++i) {
    for (const auto& t : observer.topics()) {
      if (t.name == topics::kGestureEvent.name && !t.participants.empty()) named = t.participants[0] == "my_component";
    }
    if (!named) observer.wait_for_writer("never/there", 50ms, nullptr);
  }
  EXPECT_TRUE(named);
}

TEST(RuntimeDds, TransientLocalReachesLateJoiner) {
  Context a("calib", test::test_config());
  Publisher<msg::SensorPose> pub(a, topics::kCalibration);
  msg::SensorPose p;
  p.sensor_id("kinect_b");
  p.translation().z(2.0);
  ASSERT_TRUE(pub.publish(p));
  Context late("late_fusion", test::test_config());
  test::Collector<msg::SensorPose> got;
  Subscription<msg::SensorPose> sub(late, topics::kCalibration,
                                    [&](const msg::SensorPose& s, const SampleMeta&) { got.add(s); });
  late.executor().start();
  ASSERT_TRUE(got.wait_count(1));
  EXPECT_EQ(got.items()[0].sensor_id().to_string(), "kinect_b");
  EXPECT_DOUBLE_EQ(got.items()[0].translation().z(), 2.0);
}

// A cell that runs all day: more people than Fast DDS's default of 10
// instances per writer come and go; each one who leaves is disposed, readers
// hear of it at once (with the last sample: who it was), and nothing fails.
TEST(RuntimeDds, KeyedWritersDisposeWhoLeftAndNeverRunOutOfInstances) {
  for (const auto& topic : {topics::kSkeletonFused, topics::kSkeletonTruth}) {  // best-effort and reliable
    SCOPED_TRACE(topic.name);
    Context a("lifecycle_writer", test::test_config());
    Context b("lifecycle_reader", test::test_config());
    test::Collector<std::uint32_t> seen, gone;
    std::set<std::uint32_t> alive_seen;
    Subscription<msg::Skeleton> sub(
        b, topic, [&](const msg::Skeleton& s, const SampleMeta&) { seen.add(s.person_id()); },
        [&](const msg::Skeleton& last, const SampleMeta&) {
          EXPECT_EQ(last.sensor_id().to_string(), "fused");
          gone.add(last.person_id());
        });
    Publisher<msg::Skeleton> pub(a, topic);
    b.executor().start();
    ASSERT_TRUE(pub.wait_for_matched(1, 10s));
    ASSERT_TRUE(sub.wait_for_matched(1, 10s));
    // 40 people, 3 in the cell at a time: each written a few times, then disposed.
    for (std::uint32_t id = 1; id <= 40; ++id) {
      msg::Skeleton s;
      s.sensor_id("fused");
      s.person_id(id);
      for (int k = 0; k < 3; ++k) {
        s.frame_number(static_cast<std::uint64_t>(k));
        ASSERT_TRUE(pub.publish(s)) << "person " << id;
      }
      ASSERT_TRUE(seen.wait([&](const std::vector<std::uint32_t>& v) {
        return std::find(v.begin(), v.end(), id) != v.end();
      }));
      if (id >= 3) {
        msg::Skeleton key;
        key.sensor_id("fused");
        key.person_id(id - 2);
        ASSERT_TRUE(pub.dispose(key)) << "person " << id - 2;
        EXPECT_FALSE(pub.dispose(key));  // once
      }
      EXPECT_LE(pub.live_instances(), 3u);
    }
    ASSERT_TRUE(gone.wait_count(38));
    auto g = gone.items();
    std::sort(g.begin(), g.end());
    for (std::uint32_t id = 1; id <= 38; ++id) EXPECT_EQ(g[id - 1], id);
    EXPECT_EQ(pub.live_instances(), 2u);
    EXPECT_EQ(sub.instances_held(), 2u);
    ASSERT_TRUE(b.executor().run_sync([] {}, 5s));
    for (const auto& c : a.counters()) {
      EXPECT_EQ(c->dropped.load(), 0u) << c->topic;
      if (c->topic == topic.name) {
        EXPECT_EQ(c->instances.load(), 2u);
      }
    }
    EXPECT_EQ(a.health().first, HealthState::Ok) << a.health().second;
    EXPECT_EQ(b.health().first, HealthState::Ok) << b.health().second;
  }
}

// Idle instances (a replayed recording cannot tell who left) are disposed by
// dispose_idle, on the caller's clock.
TEST(RuntimeDds, DisposeIdleEndsInstancesNotWrittenSince) {
  Context a("idle_writer", test::test_config());
  Context b("idle_reader", test::test_config());
  test::Collector<std::string> gone;
  Subscription<msg::Skeleton> sub(
      b, topics::kSkeletonRaw, [](const msg::Skeleton&, const SampleMeta&) {},
      [&](const msg::Skeleton& last, const SampleMeta&) {
        gone.add(last.sensor_id().to_string() + "/" + std::to_string(last.person_id()));
      });
  Publisher<msg::Skeleton> pub(a, topics::kSkeletonRaw);
  b.executor().start();
  ASSERT_TRUE(pub.wait_for_matched(1, 10s));
  ASSERT_TRUE(sub.wait_for_matched(1, 10s));
  msg::Skeleton s;
  s.sensor_id("kinect_a");
  for (std::uint32_t id : {1u, 2u, 3u}) {
    s.person_id(id);
    ASSERT_TRUE(pub.publish(s));
  }
  ASSERT_TRUE(b.executor().run_sync([] {}, 5s));
  const auto cut = a.clock().monotonic_ns();
  s.person_id(2);
  // Written again after the cut: stays. (Best effort: the reader must have it
  // alive before the others' disposal, so write until it has.)
  ASSERT_TRUE(pub.publish(s));
  EXPECT_EQ(pub.dispose_idle(cut), 2u);
  EXPECT_EQ(pub.live_instances(), 1u);
  ASSERT_TRUE(gone.wait_count(2));
  auto g = gone.items();
  std::sort(g.begin(), g.end());
  EXPECT_EQ(g, (std::vector<std::string>{"kinect_a/1", "kinect_a/3"}));
}

// A write DDS refuses is never silent: counted, and the component is DEGRADED.
TEST(RuntimeDds, FailedWriteMakesTheComponentDegraded) {
  Context a("cramped_writer", test::test_config());
  // A topic with room for 2 instances, and nobody leaving.
  const TopicDef<msg::Skeleton> cramped{"skelgraph/test/cramped", {Reliability::BestEffort, Durability::Volatile, 1, 2}};
  Publisher<msg::Skeleton> pub(a, cramped);
  msg::Skeleton s;
  s.sensor_id("fused");
  s.person_id(1);
  EXPECT_TRUE(pub.publish(s));
  s.person_id(2);
  EXPECT_TRUE(pub.publish(s));
  a.set_health(HealthState::Ok, "fusing 2 sensor(s)");
  EXPECT_EQ(a.health().first, HealthState::Ok);
  s.person_id(3);
  EXPECT_FALSE(pub.publish(s));
  const auto [state, message] = a.health();
  EXPECT_EQ(state, HealthState::Degraded);
  EXPECT_NE(message.find("1 write(s) failed on skelgraph/test/cramped"), std::string::npos) << message;
  std::uint64_t dropped = 0;
  for (const auto& c : a.counters()) dropped += c->dropped.load();
  EXPECT_EQ(dropped, 1u);
  // A person leaving frees room: the next one is written.
  s.person_id(1);
  EXPECT_TRUE(pub.dispose(s));
  s.person_id(3);
  EXPECT_TRUE(pub.publish(s));
  // Still DEGRADED for a while after the failure, and for the whole run in the final report.
  EXPECT_EQ(a.health().first, HealthState::Degraded);
  EXPECT_EQ(a.health(std::chrono::nanoseconds(0)).first, HealthState::Ok);
}

// The clock is the context's (injected through the configuration): receive
// stamps come from it, so a test can drive a component's time by hand.
TEST(RuntimeDds, ReceiveStampsComeFromTheContextsClock) {
  auto config = test::test_config();
  auto fake = std::make_shared<FakeClock>(1'000'000'000);
  config.clock = fake;
  Context a("clock_writer", test::test_config());
  Context b("clock_reader", config);
  EXPECT_EQ(b.clock().now_ns(), 1'000'000'000);
  test::Collector<std::int64_t> got;
  Subscription<msg::SyncCommand> sub(b, topics::kSync, [&](const msg::SyncCommand&, const SampleMeta& m) { got.add(m.receive_ns); });
  Publisher<msg::SyncCommand> pub(a, topics::kSync);
  b.executor().start();
  ASSERT_TRUE(pub.wait_for_matched(1, 10s));
  fake->set(5'000'000'000);
  ASSERT_TRUE(pub.publish(msg::SyncCommand{}));
  ASSERT_TRUE(got.wait_count(1));
  EXPECT_EQ(got.items()[0], 5'000'000'000);
  // Another host's clock: the wall clock shifted, the monotonic one not.
  const OffsetClock ahead(system_clock(), 250'000'000);
  const auto wall = system_clock()->now_ns();
  EXPECT_NEAR(static_cast<double>(ahead.now_ns() - wall), 250e6, 50e6);
  EXPECT_NEAR(static_cast<double>(ahead.monotonic_ns() - system_clock()->monotonic_ns()), 0.0, 50e6);
}

TEST(RuntimeDds, TopicBoundToOneType) {
  Context a("typed", test::test_config());
  Publisher<msg::SyncCommand> pub(a, topics::kSync);
  const TopicDef<msg::SyncAck> wrong{topics::kSync.name, topics::kSync.qos};
  EXPECT_THROW(Publisher<msg::SyncAck>(a, wrong), std::runtime_error);
}

TEST(RuntimeDds, UnknownProfileIsAClearError) {
  auto c = test::test_config();
  c.profile = "nosuchprofile";
  try {
    Context ctx("x", c);
    FAIL();
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("nosuchprofile"), std::string::npos) << m;
    EXPECT_NE(m.find("loopback"), std::string::npos) << m;  // lists what exists
  }
}

namespace {
// Local addresses of every UDP socket in this network namespace, as hex "ADDR:PORT".
std::vector<std::string> udp_local_addresses() {
  std::vector<std::string> out;
  std::ifstream in("/proc/net/udp");
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream is(line);
    std::string slot, local;
    is >> slot >> local;
    out.push_back(local);
  }
  return out;
}
}  // namespace

TEST(RuntimeDds, LoopbackProfileBindsOnlyTo127001AndJoinsNoMulticast) {
  // This test runs in a private network namespace, so every socket listed is ours.
  Context a("loop_a", test::test_config());
  Context b("loop_b", test::test_config());
  Publisher<msg::SyncCommand> pub(a, topics::kSync);
  Subscription<msg::SyncCommand> sub(b, topics::kSync, [](const msg::SyncCommand&, const SampleMeta&) {});
  ASSERT_TRUE(pub.wait_for_matched(1, 10s));
  const auto sockets = udp_local_addresses();
  ASSERT_GE(sockets.size(), 4u);  // metatraffic + user unicast per participant
  for (const auto& s : sockets) EXPECT_EQ(s.substr(0, 8), "0100007F") << s << " is not 127.0.0.1";
  // Fast DDS's default discovery group 239.255.0.1 is "0100FFEF" in /proc/net/igmp.
  std::ifstream igmp("/proc/net/igmp");
  const std::string groups((std::istreambuf_iterator<char>(igmp)), std::istreambuf_iterator<char>());
  EXPECT_EQ(groups.find("0100FFEF"), std::string::npos) << groups;
}
