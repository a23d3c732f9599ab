// Writes an MCAP file with samples of every skelgraph wire type (simulated
// skeletons plus hand-filled others) and, beside it, the values written as
// JSON lines (our own to_json), for tests/integration/mcap_npm.mjs to compare
// with what the viewers' npm packages decode.
#include <fstream>
#include <iostream>

#include "skelgraph/msg/json.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: write_mcap_samples OUT.mcap EXPECTED.jsonl none|lz4|zstd\n";
    return 2;
  }
  mcap::WriterOptions opt;
  opt.compression = *mcap::compression_from_name(argv[3]);
  opt.chunk_size = 64 * 1024;
  recording::BagWriter bag(argv[1], opt);
  std::ofstream expected(argv[2]);
  std::uint64_t t = 1'700'000'000'000'000'000ULL;
  auto put = [&](const std::string& topic, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    bag.write(topic, value, t, t - 1000);
    expected << nlohmann::json{{"topic", topic}, {"type", msg::MessageTraits<T>::name}, {"value", value}}.dump() << "\n";
    t += 1'000'000;
  };
  // Two seconds of a simulated cell: truth and two sensors.
  sim::SimConfig cfg;
  cfg.scenario.name = "point";
  cfg.epoch_ns = static_cast<std::int64_t>(t);
  sim::Simulation sim(cfg);
  for (const auto& e : sim.advance(2.0)) {
    put(e.kind == sim::SimEvent::Kind::Truth ? "skelgraph/skeleton/truth" : "skelgraph/skeleton/raw",
        skeleton::to_msg(e.skeleton));
  }
  msg::SyncCommand tick;
  tick.kind(msg::SYNC_TICK);
  tick.session_id(7);
  tick.label("walk_1");
  tick.tick(42);
  tick.master_stamp_ns(-5);
  put("skelgraph/sync", tick);
  msg::SyncAck ack;
  ack.component_name("recorder");
  ack.host("cell-pc-2");
  ack.session_id(7);
  ack.tick(42);
  ack.receive_stamp_ns(123456789);
  put("skelgraph/sync_ack", ack);
  for (const auto& s : cfg.sensors) {
    skeleton::SensorPose p;
    p.sensor_id = s.id;
    p.pose = s.world_from_sensor();
    p.method = "ground_truth";
    p.rms_residual_m = 0.0125;
    put("skelgraph/calibration", skeleton::to_msg(p));
  }
  msg::DepthFrame depth;
  depth.sensor_id("sensor1");
  depth.width(8);
  depth.height(4);
  depth.intrinsics().fx(525.0);
  std::vector<std::uint16_t> mm(32);
  for (std::size_t i = 0; i < mm.size(); ++i) mm[i] = static_cast<std::uint16_t>(800 + 97 * i);
  depth.depth_mm(mm);
  put("skelgraph/depth", depth);
  msg::GestureEvent g;
  g.label("pointing");
  g.person_id(1);
  g.score(3.25);
  g.has_ray(true);
  g.ray_origin().y(1.4);
  g.ray_direction().x(0.6);
  g.ray_direction().y(-0.8);
  g.has_target(true);
  g.target().x(1.05);
  put("skelgraph/gesture/event", g);
  msg::ComponentStatus st;
  st.component_name("sim");
  st.kind("sim");
  st.state(msg::STATE_DEGRADED);
  st.message("sensor2 silent");
  msg::TopicStats ts;
  ts.topic("skelgraph/skeleton/raw");
  ts.is_output(true);
  ts.count(99);
  ts.rate_hz(29.5);
  st.topics().push_back(ts);
  ts.topic("skelgraph/skeleton/truth");
  st.topics().push_back(ts);
  put("skelgraph/status", st);
  msg::RobotState robot;
  robot.robot_id("robot1");
  robot.model("UR5e");
  robot.stamp_ns(1234);
  robot.joints()[1] = -1.5708;
  robot.joint_speeds()[0] = 0.25;
  robot.tool_position().x(0.4919);
  robot.tool_speed(0.125);
  robot.speed_scale(0.5);
  robot.protective_stop(true);
  msg::Capsule link;
  link.a().y(0.1625);
  link.b().x(-0.425);
  link.radius(0.065);
  link.name("upper_arm");
  robot.capsules().push_back(link);
  put("skelgraph/robot/state", robot);
  msg::RobotCommand cmd;
  cmd.robot_id("robot1");
  cmd.kind(msg::ROBOT_SPEED_SCALE);
  cmd.value(0.3);
  cmd.source("separation");
  put("skelgraph/robot/command", cmd);
  msg::SafetyStatus safety;
  safety.robot_id("robot1");
  safety.state(msg::SAFETY_REDUCED);
  safety.speed_scale(0.3);
  safety.separation_m(0.92);
  safety.protective_m(0.55);
  safety.person_id(3);
  safety.body_part("right_hand");
  safety.robot_part("tool");
  safety.reason("person 3 right_hand / tool: 0.92 m, S_p 0.55 m");
  put("skelgraph/safety", safety);
  bag.write_metadata("session", {{"label", "walk_1"}, {"host", "cell-pc-2"}});
  bag.close();
  return 0;
}
