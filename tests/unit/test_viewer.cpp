// The viewer's core: what a frame holds, which frames a slow client gets,
// which client requests are accepted, and who may connect (access.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "skelgraph/viewer/access.hpp"
#include "skelgraph/viewer/client_command.hpp"
#include "skelgraph/viewer/outbox.hpp"
#include "skelgraph/viewer/scene.hpp"

using namespace skelgraph;
using namespace skelgraph::viewer;

namespace {

constexpr std::int64_t kMs = 1'000'000;

skeleton::Skeleton person(const std::string& sensor, std::uint32_t id, const std::string& frame, std::uint64_t n) {
  skeleton::Skeleton s;
  s.sensor_id = sensor;
  s.person_id = id;
  s.frame_id = frame;
  s.frame_number = n;
  for (std::size_t i = 0; i < skeleton::kJointCount; ++i) {
    s.joints[i].position = Eigen::Vector3d(0.1 * static_cast<double>(i), 1.0, 2.0);
    s.joints[i].confidence = skeleton::kTracked;
  }
  return s;
}

skeleton::SensorPose pose_of(const std::string& sensor) {
  skeleton::SensorPose p;
  p.sensor_id = sensor;
  p.frame_id = "world";
  // 90 degrees about +y, then 3 m along +x.
  p.pose = Eigen::Translation3d(3.0, 0.0, 0.0) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY());
  return p;
}

const nlohmann::json* find_skeleton(const nlohmann::json& frame, const std::string& stream) {
  for (const auto& s : frame["skeletons"])
    if (s["stream"] == stream) return &s;
  return nullptr;
}

}  // namespace

TEST(ViewerScene, JointStatesFromConfidence) {
  EXPECT_EQ(joint_state(1.0f), 2);
  EXPECT_EQ(joint_state(0.5f), 1);
  EXPECT_EQ(joint_state(0.0f), 0);
  EXPECT_EQ(joint_state(std::nanf("")), 0);
  EXPECT_EQ(stream_kind("fused"), StreamKind::Fused);
  EXPECT_EQ(stream_kind("truth"), StreamKind::Truth);
  EXPECT_EQ(stream_kind("kinect2"), StreamKind::Raw);
}

// A person whose stream disposed them (they left) is not drawn from then
// on, even while their last skeleton would still be young; the others are.
TEST(ViewerScene, APersonWhoLeftIsNoLongerDrawn) {
  Scene scene;
  scene.on_skeleton(person("fused", 1, "world", 1), 0);
  scene.on_skeleton(person("fused", 2, "world", 1), 0);
  EXPECT_EQ(scene.skeletons_held(), 2u);
  scene.on_gone("fused", 1);
  scene.on_gone("fused", 9);  // never seen: nothing happens
  EXPECT_EQ(scene.skeletons_held(), 1u);
  const auto f = scene.frame(10 * kMs);
  ASSERT_EQ(f["skeletons"].size(), 1u);
  EXPECT_EQ(f["skeletons"][0]["person"], 2);
}

TEST(ViewerScene, FusedJointsCarryTheRadiusOfTheir95PercentRegion) {
  skeleton::Joint j;
  EXPECT_EQ(skeleton::radius_95(j), 0.0);
  // Variances 4 cm^2 along x, 1 cm^2 along y and z: the largest axis, sqrt(7.815 * 0.0004) = 5.59 cm.
  skeleton::set_covariance(j, Eigen::Vector3d(0.0004, 0.0001, 0.0001).asDiagonal());
  EXPECT_NEAR(skeleton::radius_95(j), 0.05591, 1e-5);
  // Rotated, the same ellipsoid has the same sphere.
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  skeleton::set_covariance(j, r * Eigen::Vector3d(0.0004, 0.0001, 0.0001).asDiagonal() * r.transpose());
  EXPECT_NEAR(skeleton::radius_95(j), 0.05591, 1e-4);
  Scene scene;
  auto s = person("fused", 3, "world", 9);
  skeleton::set_covariance(s.joints[5], Eigen::Matrix3d::Identity() * 0.0001);
  scene.on_skeleton(s, 0);
  const auto f = scene.frame(1 * kMs);
  const auto* drawn = find_skeleton(f, "fused");
  ASSERT_NE(drawn, nullptr);
  EXPECT_NEAR((*drawn)["joints"][5][4].get<double>(), 0.028, 1e-9);  // sqrt(7.815e-4) = 27.96 mm
  EXPECT_EQ((*drawn)["joints"][4][4].get<double>(), 0.0);
}

TEST(ViewerScene, RawSkeletonsArePlacedWithTheirSensorsPose) {
  Scene scene;
  auto s = person("sensor1", 1, "sensor1", 7);
  s.joints[3].confidence = skeleton::kInferred;
  s.joints[4].confidence = skeleton::kLost;
  scene.on_skeleton(s, 0);  // no pose yet: counted, not drawn
  auto f = scene.frame(1 * kMs);
  EXPECT_EQ(f["skeletons"].size(), 0u);
  EXPECT_EQ(f["unplaced"], nlohmann::json::array({"sensor1"}));
  EXPECT_EQ(f["streams"]["sensor1"]["unplaced"], 1);

  EXPECT_FALSE(scene.on_pose([] {
    auto p = pose_of("sensor1");
    p.frame_id = "mocap";
    return p;
  }()));
  ASSERT_TRUE(scene.on_pose(pose_of("sensor1")));
  scene.on_skeleton(s, 10 * kMs);
  f = scene.frame(20 * kMs);
  const auto* drawn = find_skeleton(f, "sensor1");
  ASSERT_NE(drawn, nullptr);
  EXPECT_EQ((*drawn)["kind"], "raw");
  EXPECT_EQ((*drawn)["frame"], 7);
  EXPECT_EQ((*drawn)["age_ms"], 10);
  const auto& joints = (*drawn)["joints"];
  ASSERT_EQ(joints.size(), skeleton::kJointCount);
  // Joint 0 at (0, 1, 2) in the sensor frame: rotated 90 degrees about y -> (2, 1, 0), then +3 m in x.
  EXPECT_NEAR(joints[0][0].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(joints[0][1].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(joints[0][2].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(joints[0][3], 2);
  EXPECT_EQ(joints[3][3], 1);
  EXPECT_EQ(joints[4], nlohmann::json::array({0, 0, 0, 0, 0}));
  EXPECT_EQ(joints[0][4], 0.0);  // a raw skeleton: no covariance, no sphere
  EXPECT_EQ(f["unplaced"].size(), 0u);
  ASSERT_EQ(f["sensors"].size(), 1u);
  EXPECT_EQ(f["sensors"][0]["position"], nlohmann::json::array({3.0, 0.0, 0.0}));
}

TEST(ViewerScene, WorldSkeletonsPassAndOldOnesGo) {
  SceneOptions o;
  o.max_age_ns = 100 * kMs;
  Scene scene(o);
  scene.on_skeleton(person("fused", 1, "world", 1), 0);
  scene.on_skeleton(person("fused", 2, "world", 1), 50 * kMs);
  scene.on_skeleton(person("truth", 1, "world", 1), 50 * kMs);
  auto f = scene.frame(80 * kMs);
  EXPECT_EQ(f["skeletons"].size(), 3u);
  EXPECT_NEAR(find_skeleton(f, "fused")->at("joints")[1][0].get<double>(), 0.1, 1e-9);
  f = scene.frame(120 * kMs);  // person 1 of fused is 120 ms old
  EXPECT_EQ(f["skeletons"].size(), 2u);
  EXPECT_EQ(scene.skeletons_held(), 2u);
  EXPECT_GT(f["seq"].get<int>(), 1);
}

TEST(ViewerScene, RatesPerStream) {
  Scene scene;
  for (int i = 0; i <= 30; ++i) scene.on_skeleton(person("fused", 1, "world", i), i * 33 * kMs);
  const auto f = scene.frame(30 * 33 * kMs);
  EXPECT_NEAR(f["streams"]["fused"]["rate_hz"].get<double>(), 30.3, 0.1);
  EXPECT_EQ(f["streams"]["fused"]["kind"], "fused");
}

TEST(ViewerScene, GesturesAndStatusExpire) {
  SceneOptions o;
  o.gesture_hold_ns = 1000 * kMs;
  o.status_max_age_ns = 2000 * kMs;
  Scene scene(o);
  scene.on_gesture({{"label", "pointing"}, {"person_id", 1}}, 0);
  scene.on_status("fusion", {{"component_name", "fusion"}, {"state", "STATE_DEGRADED"}}, 0);
  scene.on_status("fusion", {{"component_name", "fusion"}, {"state", "STATE_OK"}}, 500 * kMs);
  scene.on_player("play", {{"player", "play"}, {"paused", true}});
  auto f = scene.frame(900 * kMs);
  ASSERT_EQ(f["gestures"].size(), 1u);
  EXPECT_EQ(f["gestures"][0]["age_ms"], 900);
  ASSERT_EQ(f["status"].size(), 1u);
  EXPECT_EQ(f["status"][0]["state"], "STATE_OK");
  EXPECT_EQ(f["players"].size(), 1u);
  f = scene.frame(1100 * kMs);
  EXPECT_EQ(f["gestures"].size(), 0u);
  EXPECT_EQ(f["status"].size(), 1u);
  f = scene.frame(2600 * kMs);
  EXPECT_EQ(f["status"].size(), 0u);
}

TEST(ViewerOutbox, ASlowClientGetsTheNewestFrameOnly) {
  Outbox box(2);
  auto msg = [](const char* s) { return std::make_shared<const std::string>(s); };
  EXPECT_TRUE(box.empty());
  EXPECT_EQ(box.take(), nullptr);
  box.push_frame(msg("f1"));
  box.push_frame(msg("f2"));
  box.push_frame(msg("f3"));
  EXPECT_EQ(box.dropped_frames(), 2u);
  box.push_reply(msg("r1"));
  box.push_reply(msg("r2"));
  box.push_reply(msg("r3"));  // over max_replies: r1 goes
  EXPECT_EQ(box.dropped_replies(), 1u);
  EXPECT_EQ(*box.take(), "r2");
  EXPECT_EQ(*box.take(), "r3");
  EXPECT_EQ(*box.take(), "f3");
  EXPECT_TRUE(box.empty());
  EXPECT_EQ(box.take(), nullptr);
  box.push_frame(msg("f4"));  // the slot was emptied by take(): nothing dropped
  EXPECT_EQ(box.dropped_frames(), 2u);
}

TEST(ViewerClientCommand, AcceptsPlayAndPing) {
  auto p = parse_client_message(R"({"cmd":"play","kind":"speed","value":2,"target":"player"})");
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.command.type, ClientCommand::Type::Play);
  EXPECT_EQ(p.command.play_kind, "speed");
  EXPECT_EQ(p.command.value, 2.0);
  EXPECT_EQ(p.command.target, "player");
  p = parse_client_message(R"({"cmd":"play","kind":"step"})");
  ASSERT_TRUE(p.ok);
  EXPECT_EQ(p.command.value, 1.0);
  p = parse_client_message(R"({"cmd":"ping","id":"abc"})");
  ASSERT_TRUE(p.ok);
  EXPECT_EQ(p.command.ping_id, "abc");
}

TEST(ViewerClientCommand, RefusesMalformedRequestsSayingWhy) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not json", "not JSON"},
      {"[1]", "JSON object"},
      {R"({"kind":"pause"})", "\"cmd\""},
      {R"({"cmd":"rewind"})", "unknown cmd 'rewind'"},
      {R"({"cmd":"play"})", "\"kind\""},
      {R"({"cmd":"play","kind":"rewind"})", "unknown kind 'rewind'"},
      {R"({"cmd":"play","kind":"seek"})", "seconds from the start"},
      {R"({"cmd":"play","kind":"speed"})", "expected \"value\""},
      {R"({"cmd":"play","kind":"speed","value":"fast"})", "must be a number"},
      {R"({"cmd":"play","kind":"pause","target":7})", "\"target\""},
      {R"({"cmd":"play","kind":"pause","target":")" + std::string(80, 'a') + "\"}", "longer than 63"},
      {std::string(kMaxClientMessage + 1, ' '), "at most"},
  };
  for (const auto& [text, why] : cases) {
    const auto p = parse_client_message(text);
    EXPECT_FALSE(p.ok) << text;
    EXPECT_NE(p.error.find(why), std::string::npos) << text << " -> " << p.error;
  }
}

// The robot and its monitor's verdict in the frame: capsules (m, to the
// mm), the tool, the safety state; gone when not heard of for a while.
TEST(ViewerScene, RobotsAreDrawnWithTheirCapsulesAndSafetyState) {
  Scene scene;
  const nlohmann::json cap = {{"a", {{"x", 0.0}, {"y", 0.1}, {"z", 1.9}}},
                              {"b", {{"x", 0.0}, {"y", 0.6}, {"z", 1.9}}},
                              {"radius", 0.08},
                              {"name", "base"}};
  scene.on_robot({{"robot_id", "robot1"},
                  {"capsules", {cap}},
                  {"tool_position", {{"x", 0.3}, {"y", 0.6}, {"z", 1.35}}},
                  {"speed_scale", 0.5},
                  {"protective_stop", false}},
                 0);
  auto f = scene.frame(1'000'000);
  ASSERT_EQ(f["robots"].size(), 1u);
  const auto& r = f["robots"][0];
  EXPECT_EQ(r["id"], "robot1");
  EXPECT_EQ(r["capsules"][0], (nlohmann::json{0.0, 0.1, 1.9, 0.0, 0.6, 1.9, 0.08}));
  EXPECT_EQ(r["tool"], (nlohmann::json{0.3, 0.6, 1.35}));
  EXPECT_TRUE(r["safety"].is_null());  // no verdict yet
  scene.on_safety({{"robot_id", "robot1"},
                   {"state", "PROTECTIVE_STOP"},
                   {"separation_m", 0.42},
                   {"protective_m", 0.61},
                   {"person_id", 3},
                   {"body_part", "right_hand"},
                   {"robot_part", "tool"},
                   {"reason", "person 3 right_hand / tool: 0.42 m, S_p 0.61 m"}},
                  2'000'000);
  f = scene.frame(3'000'000);
  EXPECT_EQ(f["robots"][0]["safety"]["state"], "PROTECTIVE_STOP");
  EXPECT_EQ(f["robots"][0]["safety"]["body_part"], "right_hand");
  // Not heard of for longer than status_max_age_ns: not drawn.
  EXPECT_TRUE(scene.frame(6'000'000'000).at("robots").empty());
}

// Who may connect: addresses, tokens, where a request carries its token.
TEST(ViewerAccess, LoopbackAddresses) {
  EXPECT_TRUE(is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(is_loopback_address("127.3.2.1"));
  EXPECT_TRUE(is_loopback_address("::1"));
  EXPECT_FALSE(is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(is_loopback_address("192.0.2.10"));
  EXPECT_FALSE(is_loopback_address("::"));
  EXPECT_THROW(is_loopback_address("localhost"), std::runtime_error);
}

TEST(ViewerAccess, TokensByHashWithExpiry) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");  // FIPS 180-2
  const auto t = new_token();
  EXPECT_EQ(t.size(), 64u);
  EXPECT_NE(t, new_token());
  const std::vector<TokenEntry> tokens{{sha256_hex(t), 1000, "bob"}, {sha256_hex("old"), 500, "dave"}};
  EXPECT_TRUE(check_token(tokens, t, 999).ok);
  EXPECT_EQ(check_token(tokens, t, 999).who, "bob");
  const auto late = check_token(tokens, t, 1000);
  EXPECT_FALSE(late.ok);
  EXPECT_NE(late.reason.find("expired"), std::string::npos);
  EXPECT_TRUE(check_token(tokens, "old", 400).ok);
  EXPECT_EQ(check_token(tokens, "nope", 0).reason, "unknown token");
  EXPECT_EQ(check_token(tokens, "", 0).reason, "no credentials");
}

TEST(ViewerAccess, TokenOfRequest) {
  EXPECT_EQ(token_of_request("Bearer abc", "skelgraph_token=def", "/?token=ghi").token, "abc");
  EXPECT_EQ(token_of_request("", "a=1; skelgraph_token=def; b=2", "/?token=ghi").token, "def");
  const auto q = token_of_request("", "a=1", "/index.html?x=1&token=ghi");
  EXPECT_EQ(q.token, "ghi");
  EXPECT_TRUE(q.from_query);
  EXPECT_EQ(token_of_request("Basic xyz", "", "/").token, "");
  EXPECT_EQ(target_without_token("/?token=ghi"), "/");
  EXPECT_EQ(target_without_token("/a?x=1&token=ghi&y=2"), "/a?x=1&y=2");
  EXPECT_EQ(target_without_token("/a"), "/a");
}

TEST(ViewerAccess, TokensFileReadAgainWhenItChanges) {
  const auto dir = std::filesystem::temp_directory_path() / ("skelgraph_tokens_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = (dir / "tokens").string();
  TokenStore store(file);
  EXPECT_FALSE(store.check("t1", 0).ok);  // no file: nobody
  { std::ofstream(file) << "# comment\n" << token_line({sha256_hex("t1"), 2000, "bob"}) << "\n"; }
  EXPECT_TRUE(store.check("t1", 0).ok);
  // Each change with its own modification time (not left to the file system's clock granularity).
  const auto t0 = std::filesystem::last_write_time(file);
  { std::ofstream(file) << token_line({sha256_hex("t2"), 2000, "carol"}) << "\n"; }
  std::filesystem::last_write_time(file, t0 + std::chrono::seconds(1));
  EXPECT_FALSE(store.check("t1", 0).ok);
  EXPECT_TRUE(store.check("t2", 0).ok);
  { std::ofstream(file) << "not a token line\n"; }
  std::filesystem::last_write_time(file, t0 + std::chrono::seconds(2));
  const auto bad = store.check("t2", 0);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.reason.find(file + ":1"), std::string::npos) << bad.reason;
  EXPECT_THROW(read_tokens(file), std::runtime_error);
  std::filesystem::remove_all(dir);
}
