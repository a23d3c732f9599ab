// The viewer component on a fake clock, driven through its topics and a
// WebSocket page of the test's: a sensor's pose and its raw skeleton, a fused
// skeleton and a gesture event go in; the frames the page gets show them in
// the world frame; a skeleton its source disposed goes at once, one not
// updated for max_age_s of the viewer's clock goes then; a page's play request
// comes out on skelgraph/play/control, a ping is answered, a malformed message
// is refused and counted.

#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "../support/test_support.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/graph.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"
#include "skelgraph/viewer/viewer_component.hpp"

using namespace skelgraph;
using namespace skelgraph::runtime;
using namespace std::chrono_literals;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Eigen::Vector3d;
using skeleton::JointId;

namespace {

// A page: a WebSocket on the viewer, read frame by frame.
class Page {
 public:
  explicit Page(int port) : ws_(ioc_) {
    tcp::resolver resolver(ioc_);
    net::connect(beast::get_lowest_layer(ws_), resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.handshake("127.0.0.1", "/ws");
  }
  void send(const std::string& text) { ws_.write(net::buffer(text)); }
  // Reads messages until `pred` holds for one (returned), or `timeout` passes (null).
  nlohmann::json read_until(const std::function<bool(const nlohmann::json&)>& pred, std::chrono::seconds timeout = 10s) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      beast::flat_buffer buf;
      ws_.read(buf);  // frames come rate_hz times a second
      auto m = nlohmann::json::parse(beast::buffers_to_string(buf.data()));
      if (pred(m)) return m;
    }
    return nullptr;
  }

 private:
  net::io_context ioc_;
  websocket::stream<tcp::socket> ws_;
};

const nlohmann::json* skeleton_of(const nlohmann::json& frame, const std::string& stream, const std::string& kind) {
  for (const auto& s : frame["skeletons"]) {
    if (s["stream"] == stream && s["kind"] == kind) return &s;
  }
  return nullptr;
}

Vector3d joint(const nlohmann::json& s, JointId j) {
  const auto& a = s["joints"][static_cast<std::size_t>(j)];
  return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
}

skeleton::Skeleton standing(const std::string& sensor, const std::string& frame_id, const Vector3d& torso,
                            std::int64_t stamp_ns) {
  skeleton::Skeleton s;
  s.sensor_id = sensor;
  s.person_id = 4;
  s.frame_id = frame_id;
  s.stamp_ns = stamp_ns;
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    s.joints[j].position = torso + Vector3d(0, 0.05 * static_cast<double>(j) - 0.4, 0);
    s.joints[j].confidence = skeleton::kTracked;
  }
  s[JointId::Torso].position = torso;
  return s;
}

}  // namespace

TEST(ViewerComponent, PagesSeeTheCellAndDriveItsPlayers) {
  auto clock = std::make_shared<FakeClock>(13'000'000'000'000);
  auto config = test::test_config();
  config.clock = clock;
  const auto registry = builtin_registry();
  Graph graph(registry, config, 100ms);
  auto& viewer = dynamic_cast<viewer::ViewerComponent&>(graph.add(
      "viewer", "viewer",
      registry.find("viewer")->info.params.resolve({{"port", "0", "test"}, {"max_age_s", "0.5", "test"}}, "viewer")));
  const auto url = viewer.url();  // http://127.0.0.1:PORT/
  const int port = std::stoi(url.substr(url.rfind(':') + 1));

  Context ctx("test_cell", config);
  Publisher<msg::SensorPose> poses(ctx, topics::kCalibration);
  Publisher<msg::Skeleton> raw(ctx, topics::kSkeletonRaw);
  Publisher<msg::Skeleton> fused(ctx, topics::kSkeletonFused);
  Publisher<msg::GestureEvent> gestures(ctx, topics::kGestureEvent);
  test::Collector<msg::PlayControl> controls;
  Subscription<msg::PlayControl> control_sub(ctx, topics::kPlayControl,
                                             [&](const msg::PlayControl& c, const SampleMeta&) { controls.add(c); });
  ctx.executor().start();
  graph.start();
  ASSERT_TRUE(raw.wait_for_matched(1, 10s));
  ASSERT_TRUE(fused.wait_for_matched(1, 10s));
  ASSERT_TRUE(gestures.wait_for_matched(1, 10s));
  ASSERT_TRUE(control_sub.wait_for_matched(1, 10s));
  const auto& viewer_ctx = graph.context("viewer");
  ASSERT_TRUE(test::wait_input_matched(viewer_ctx, topics::kSkeletonRaw.name));  // best effort: a first sample would be lost
  ASSERT_TRUE(test::wait_input_matched(viewer_ctx, topics::kSkeletonFused.name));

  skeleton::SensorPose pose;
  pose.sensor_id = "sensor1";
  pose.pose.translation() = Vector3d(0, 1.2, 2);
  pose.method = "manual";
  ASSERT_TRUE(poses.publish(skeleton::to_msg(pose)));
  ASSERT_TRUE(test::wait_input_count(viewer_ctx, topics::kCalibration.name, 1));
  // Sensor frame: the torso 1 m in front of sensor1 (z), so at (0, 1.2, 3) in the world.
  ASSERT_TRUE(raw.publish(skeleton::to_msg(standing("sensor1", "sensor1", Vector3d(0, 0, 1), clock->now_ns()))));
  ASSERT_TRUE(fused.publish(skeleton::to_msg(standing("fused", "world", Vector3d(0.5, 1.0, 2.5), clock->now_ns()))));
  msg::GestureEvent g;
  g.label("point");
  g.person_id(4);
  g.source("fused");
  g.has_target(true);
  g.target().x(1.5);
  g.target_name("floor");
  ASSERT_TRUE(gestures.publish(g));
  ASSERT_TRUE(test::wait_input_count(viewer_ctx, topics::kSkeletonRaw.name, 1));
  ASSERT_TRUE(test::wait_input_count(viewer_ctx, topics::kSkeletonFused.name, 1));
  ASSERT_TRUE(test::wait_input_count(viewer_ctx, topics::kGestureEvent.name, 1));

  Page page(port);
  const auto frame = page.read_until([](const nlohmann::json& m) {
    return m["type"] == "frame" && skeleton_of(m, "sensor1", "raw") && skeleton_of(m, "fused", "fused") &&
           !m["gestures"].empty();
  });
  ASSERT_FALSE(frame.is_null()) << "no frame showed the skeletons and the gesture";
  EXPECT_LT((joint(*skeleton_of(frame, "sensor1", "raw"), JointId::Torso) - Vector3d(0, 1.2, 3)).norm(), 1e-6);
  EXPECT_LT((joint(*skeleton_of(frame, "fused", "fused"), JointId::Torso) - Vector3d(0.5, 1.0, 2.5)).norm(), 1e-6);
  EXPECT_EQ(frame["gestures"][0]["label"], "point");
  ASSERT_EQ(frame["sensors"].size(), 1u);
  EXPECT_EQ(frame["sensors"][0]["id"], "sensor1");
  EXPECT_TRUE(frame["unplaced"].empty()) << frame["unplaced"];

  // The raw skeleton's source disposes it (the tracker lost the person): gone from the next frames.
  msg::Skeleton key;
  key.sensor_id("sensor1");
  key.person_id(4);
  ASSERT_TRUE(raw.dispose(key));
  EXPECT_FALSE(page.read_until([](const nlohmann::json& m) {
                     return m["type"] == "frame" && !skeleton_of(m, "sensor1", "raw") && skeleton_of(m, "fused", "fused");
                   }).is_null());
  // Nothing new for longer than max_age_s on the viewer's clock: the fused one is no longer drawn.
  clock->advance(600'000'000);
  EXPECT_FALSE(page.read_until([](const nlohmann::json& m) {
                     return m["type"] == "frame" && m["skeletons"].empty();
                   }).is_null());

  // The page drives a player, pings, and sends something malformed.
  page.send(R"({"cmd":"play","kind":"step","value":2,"target":"player"})");
  ASSERT_TRUE(controls.wait_count(1, 10s));
  EXPECT_EQ(controls.items()[0].kind(), msg::PLAY_STEP);
  EXPECT_EQ(controls.items()[0].value(), 2.0);
  EXPECT_EQ(controls.items()[0].target(), "player");
  page.send(R"({"cmd":"ping","id":17})");
  EXPECT_FALSE(page.read_until([](const nlohmann::json& m) { return m["type"] == "pong" && m["id"] == 17; }).is_null());
  page.send(R"({"cmd":"play","kind":"rewind"})");
  const auto error = page.read_until([](const nlohmann::json& m) { return m["type"] == "error"; });
  ASSERT_FALSE(error.is_null());
  EXPECT_NE(error["message"].get<std::string>().find("rewind"), std::string::npos) << error;
  graph.stop();

  const auto reports = graph.report();
  ASSERT_EQ(reports.size(), 1u);
  const auto& d = reports[0].details;
  EXPECT_EQ(d["connections"], 1) << d;
  EXPECT_EQ(d["bad_messages"], 1) << d;
  EXPECT_GT(d["frames_made"].get<int>(), 0) << d;
}
