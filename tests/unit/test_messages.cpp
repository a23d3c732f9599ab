#include <gtest/gtest.h>

#include <string>

#include "skelgraph/msg/idl_text.hpp"
#include "skelgraph/msg/json.hpp"
#include "skelgraph/msg/message_table.hpp"
#include "skelgraph/msg/messages.hpp"
#include "skelgraph/msg/raw_type.hpp"

#include <fastrtps/utils/md5.h>

using namespace skelgraph::msg;
using eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {
template <class T>
std::vector<std::uint8_t> serialize(T& value) {
  typename MessageTraits<T>::PubSubType support;
  SerializedPayload_t payload(support.getSerializedSizeProvider(&value)());
  EXPECT_TRUE(support.serialize(&value, &payload));
  return std::vector<std::uint8_t>(payload.data, payload.data + payload.length);
}
}  // namespace

TEST(Messages, SkeletonDecodesToJsonWithNamedJoints) {
  Skeleton s;
  s.sensor_id("kinect_a");
  s.person_id(3);
  s.frame_id("kinect_a");
  s.stamp_ns(123456789);
  s.frame_number(42);
  s.joints()[JOINT_RIGHT_HAND].position().x(0.25);
  s.joints()[JOINT_RIGHT_HAND].confidence(0.5f);
  s.joints()[JOINT_HEAD].orientation().w(1.0);
  const auto* info = find_message("skelgraph::msg::Skeleton");
  ASSERT_NE(info, nullptr);
  EXPECT_TRUE(info->keyed);
  const auto j = info->decode(serialize(s));
  EXPECT_EQ(j["sensor_id"], "kinect_a");
  EXPECT_EQ(j["person_id"], 3);
  EXPECT_EQ(j["frame_number"], 42);
  ASSERT_EQ(j["joints"].size(), 15u);
  EXPECT_EQ(j["joints"][JOINT_RIGHT_HAND]["name"], "right_hand");
  EXPECT_DOUBLE_EQ(j["joints"][JOINT_RIGHT_HAND]["position"]["x"].get<double>(), 0.25);
  EXPECT_FLOAT_EQ(j["joints"][JOINT_RIGHT_HAND]["confidence"].get<float>(), 0.5f);
  EXPECT_DOUBLE_EQ(j["joints"][JOINT_HEAD]["orientation"]["w"].get<double>(), 1.0);
}

TEST(Messages, SyncCommandDecodesWithKindName) {
  SyncCommand c;
  c.kind(SYNC_TICK);
  c.session_id(9);
  c.label("walk");
  c.tick(17);
  c.master_stamp_ns(-5);
  const auto* info = find_message("skelgraph::msg::SyncCommand");
  ASSERT_NE(info, nullptr);
  EXPECT_FALSE(info->keyed);
  const auto j = info->decode(serialize(c));
  EXPECT_EQ(j["kind"], "TICK");
  EXPECT_EQ(j["label"], "walk");
  EXPECT_EQ(j["tick"], 17);
  EXPECT_EQ(j["master_stamp_ns"], -5);
}

TEST(Messages, TableCoversEveryTopLevelTypeOnce) {
  const std::vector<std::string> expected = {"Skeleton",   "SyncCommand",  "SyncControl", "SyncAck",
                                             "SensorPose", "DepthFrame",   "GestureEvent", "ComponentStatus",
                                             "ClockOffset", "TickFrames", "SensorFrame", "GestureState", "PointCloud",
                                             "PlayControl", "PlayState"};
  ASSERT_EQ(message_table().size(), expected.size());
  for (const auto& name : expected) {
    const auto* info = find_message("skelgraph::msg::" + name);
    ASSERT_NE(info, nullptr) << name;
    std::unique_ptr<eprosima::fastdds::dds::TopicDataType> support(info->make_type_support());
    EXPECT_EQ(support->getName(), "skelgraph::msg::" + name);
    // The IDL text we ship as schema defines every type.
    EXPECT_NE(std::string(idl_text()).find("struct " + name + " {"), std::string::npos) << name;
  }
  EXPECT_EQ(find_message("std_msgs::msg::String"), nullptr);
}

TEST(Messages, TruncatedPayloadIsAnError) {
  SyncAck a;
  a.component_name("recorder_a");
  auto bytes = serialize(a);
  bytes.resize(6);
  EXPECT_THROW(find_message("skelgraph::msg::SyncAck")->decode(bytes), std::runtime_error);
}

TEST(Messages, RawTypeKeepsPayloadBytesExactly) {
  SensorPose p;
  p.sensor_id("b");
  p.translation().x(1.5);
  const auto bytes = serialize(p);
  RawPubSubType raw("skelgraph::msg::SensorPose", true);
  EXPECT_EQ(raw.getName(), std::string("skelgraph::msg::SensorPose"));
  RawSample in{bytes};
  SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  ASSERT_TRUE(raw.serialize(&in, &payload));
  RawSample out;
  ASSERT_TRUE(raw.deserialize(&payload, &out));
  EXPECT_EQ(out.payload, bytes);
  // And what went through the raw type still decodes with the real one.
  EXPECT_DOUBLE_EQ(find_message("skelgraph::msg::SensorPose")->decode(out.payload)["translation"]["x"].get<double>(),
                   1.5);
  RawSample tiny{{0, 1}};
  EXPECT_FALSE(raw.serialize(&tiny, &payload));  // shorter than an encapsulation header
}

TEST(Messages, JointNames) {
  EXPECT_STREQ(joint_name(JOINT_HEAD), "head");
  EXPECT_STREQ(joint_name(JOINT_RIGHT_FOOT), "right_foot");
  EXPECT_STREQ(joint_name(static_cast<JointId>(99)), "unknown");
}

// An instance's key hash is the MD5 of its key in big-endian CDR with zero
// padding, whatever keys the same type support hashed before (the generated
// code hashed leftover padding: one person got several instances when a
// participant wrote "truth" and "sensor1" skeletons; idl/patch_generated.cmake).
TEST(Messages, KeyHashIsTheKeysAloneWhateverCameBefore) {
  SkeletonPubSubType support;
  const auto hash = [&](const std::string& sensor, std::uint32_t person) {
    Skeleton s;
    s.sensor_id(sensor);
    s.person_id(person);
    s.frame_number(person * 7u);  // not part of the key
    eprosima::fastrtps::rtps::InstanceHandle_t h;
    EXPECT_TRUE(support.getKey(&s, &h, false));
    std::vector<std::uint8_t> v;
    for (unsigned i = 0; i < 16; ++i) v.push_back(h.value[i]);
    return v;
  };
  const auto truth = hash("truth", 1);
  EXPECT_EQ(hash("sensor123", 0xffffffffu).size(), 16u);  // fills the padding after "truth" with other bytes
  EXPECT_EQ(hash("truth", 1), truth);
  // Independently: length 6 ("truth" and its terminator), 2 bytes of zero padding, then the id.
  const std::uint8_t key[] = {0, 0, 0, 6, 't', 'r', 'u', 't', 'h', 0, 0, 0, 0, 0, 0, 1};
  MD5 md5;
  md5.init();
  md5.update(key, sizeof key);
  md5.finalize();
  EXPECT_EQ(truth, std::vector<std::uint8_t>(md5.digest, md5.digest + 16));
  EXPECT_NE(hash("truth", 2), truth);
}
