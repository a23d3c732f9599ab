// Writes a recording as skelgraph wrote them before Skeleton schema 2 (the
// capture stamps and covariance): the schema stored is the IDL without them,
// and every Skeleton payload is encoded here field by field in schema 1's
// layout, independently of the reader's code. Four seconds of the simulated
// two-sensor cell: truth, raw skeletons, sensor poses, sync ticks. For
// tests/integration/old_recording.sh.
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <iostream>
#include <string>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/idl_text.hpp"
#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;

namespace {

std::string cut(std::string text, const std::string& from, const std::string& to) {
  const auto a = text.find(from);
  const auto b = a == std::string::npos ? a : text.find(to, a);
  if (b == std::string::npos) throw std::runtime_error("the IDL no longer has '" + from + "' ... '" + to + "'");
  return text.erase(a, b + to.size() - a);
}

// Schema 1 of skelgraph::msg::Skeleton, little-endian CDR with its encapsulation.
std::string skeleton_schema1(const skeleton::Skeleton& s) {
  std::vector<char> buf(4096);
  eprosima::fastcdr::FastBuffer fb(buf.data(), buf.size());
  eprosima::fastcdr::Cdr cdr(fb, eprosima::fastcdr::Cdr::LITTLE_ENDIANNESS, eprosima::fastcdr::Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  cdr << s.sensor_id << s.person_id << s.frame_id << s.stamp_ns << s.frame_number;
  for (const auto& j : s.joints) {
    cdr << j.position.x() << j.position.y() << j.position.z();
    cdr << j.orientation.w() << j.orientation.x() << j.orientation.y() << j.orientation.z();
    cdr << j.confidence << j.sensor_mask;
  }
  return std::string(buf.data(), cdr.getSerializedDataLength());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_schema1_recording OUT.mcap\n";
    return 2;
  }
  // The IDL as it was: Skeleton without its schema-2 fields, no PositionCovariance.
  std::string idl = cut(msg::idl_text(), "// A joint position's uncertainty", "};\n\n");
  idl = cut(idl, "    // Schema 2.", "covariance[15];  // per joint (JointId order); all zero: not given\n");
  if (idl.find("capture_oldest_ns") != std::string::npos) throw std::runtime_error("schema-2 fields left in the IDL");

  mcap::Writer w(argv[1]);
  std::map<std::string, std::uint16_t> channels;
  std::map<std::uint16_t, std::uint32_t> sequence;
  auto put = [&](const std::string& topic, const std::string& type, bool keyed, const std::string& bytes,
                 std::int64_t t) {
    auto& id = channels[topic];
    if (id == 0) {
      id = w.add_channel(w.add_schema(type, "omgidl", idl), topic, "cdr",
                         {{"dds_type", type}, {"keyed", keyed ? "true" : "false"}});
    }
    w.write({id, sequence[id]++, static_cast<std::uint64_t>(t), static_cast<std::uint64_t>(t), bytes});
  };
  auto put_msg = [&](const std::string& topic, const auto& value, std::int64_t t) {
    using T = std::decay_t<decltype(value)>;
    const auto b = msg::to_cdr(value);
    put(topic, msg::MessageTraits<T>::name, T::isKeyDefined(), std::string(b.begin(), b.end()), t);
  };
  const std::string skel = msg::MessageTraits<msg::Skeleton>::name;

  sim::SimConfig cfg;
  cfg.scenario.name = "walk";
  cfg.epoch_ns = 1'700'000'000'000'000'000LL;
  sim::Simulation sim(cfg);
  for (const auto& s : cfg.sensors) {
    skeleton::SensorPose p;
    p.sensor_id = s.id;
    p.pose = s.world_from_sensor();
    p.method = "ground_truth";
    p.stamp_ns = cfg.epoch_ns;
    put_msg("skelgraph/calibration", skeleton::to_msg(p), cfg.epoch_ns);
  }
  std::uint64_t tick = 0;
  for (double t = 1.0 / 30; t <= 4.0 + 1e-9; t += 1.0 / 30) {
    for (const auto& e : sim.advance(t)) {
      if (e.kind == sim::SimEvent::Kind::Truth) {
        put("skelgraph/skeleton/truth", skel, true, skeleton_schema1(e.skeleton), e.skeleton.stamp_ns);
      } else if (e.kind == sim::SimEvent::Kind::Raw) {
        put("skelgraph/skeleton/raw", skel, true, skeleton_schema1(e.skeleton), e.skeleton.stamp_ns + 2'000'000);
      }
    }
    msg::SyncCommand c;
    c.kind(msg::SYNC_TICK);
    c.session_id(1);
    c.tick(++tick);
    const auto now = cfg.epoch_ns + static_cast<std::int64_t>(t * 1e9) + 3'000'000;
    c.master_stamp_ns(now);
    put_msg("skelgraph/sync", c, now);
  }
  w.write_metadata({"session", {{"label", "walk_1"}, {"host", "cell-pc-1"}, {"session_id", "1"}}});
  w.close();
  std::cout << "wrote " << argv[1] << ": " << tick << " ticks, skeletons in schema 1\n";
  return 0;
}
