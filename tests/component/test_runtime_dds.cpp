// The DDS layer on its own: typed and raw endpoints, discovery, QoS, the
// loopback profile. Runs inside tests/netns-lo.sh (a namespace with only lo).

#include <gtest/gtest.h>

#include <fstream>
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
