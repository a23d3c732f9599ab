#include "skelgraph/sim/sim_files.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include <opencv2/core.hpp>  // cv::RNG

#include "skelgraph/playback/bvh.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::sim {

namespace {
void write_file(const std::filesystem::path& path, const playback::Recording& rec) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  playback::write_generic_csv(rec, out);
  if (!out.flush()) throw std::runtime_error("error writing " + path.string());
}
}  // namespace

ExportSummary export_simulation(const SimConfig& cfg, const std::string& dir, const SimProgress& progress) {
  Simulation sim(cfg);
  std::map<std::string, std::string> meta{{"source", "skelgraph sim"},
                                          {"scenario", cfg.scenario.name},
                                          {"seed", std::to_string(cfg.scenario.seed)},
                                          {"repeats", std::to_string(cfg.scenario.repeats)},
                                          {"people", std::to_string(cfg.scenario.people)},
                                          {"profile", cfg.profile}};
  playback::Recording truth;
  truth.format = "generic";
  truth.metadata = meta;
  truth.metadata["frame"] = "world";
  std::vector<playback::Recording> raw(cfg.sensors.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const auto& s = cfg.sensors[i];
    raw[i].format = "generic";
    raw[i].metadata = meta;
    const Eigen::Vector3d p = s.position;
    raw[i].metadata["sensor_pose"] = std::to_string(p.x()) + "," + std::to_string(p.y()) + "," + std::to_string(p.z()) +
                                     " yaw " + std::to_string(s.yaw * 180.0 / M_PI) + " pitch " +
                                     std::to_string(s.pitch * 180.0 / M_PI);
    raw[i].metadata["clock_offset_ms"] = std::to_string(s.clock_offset_s * 1e3);
  }
  std::filesystem::create_directories(dir);
  std::ofstream phases(std::filesystem::path(dir) / "phases.csv");
  phases << "stamp_ns,person_id,phase\n";
  const double step = 5.0;  // s of simulated time per batch (progress)
  for (double t = step;; t += step) {
    for (auto& e : sim.advance(t)) {
      if (e.kind == SimEvent::Kind::Truth) {
        for (const auto& a : sim.scenario().at(e.t).actors) {
          if (a.person_id == e.actor) phases << e.skeleton.stamp_ns << "," << a.person_id << "," << a.phase << "\n";
        }
        truth.frames.push_back(std::move(e.skeleton));
      } else {
        raw[e.sensor].frames.push_back(std::move(e.skeleton));
      }
    }
    if (progress) progress(std::min(t, sim.duration()), sim.duration());
    if (sim.finished()) break;
  }
  nlohmann::json files = nlohmann::json::object();
  write_file(std::filesystem::path(dir) / "truth.csv", truth);
  files["truth.csv"] = truth.frames.size();
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const auto name = "raw_" + cfg.sensors[i].id + ".csv";
    write_file(std::filesystem::path(dir) / name, raw[i]);
    files[name] = raw[i].frames.size();
  }
  // The truth as motion capture (BVH, cm, position channels): what `bag
  // import-bvh` reads, when one person is there from start to end at the truth rate.
  const auto evenly = [&] {
    if (truth.frames.size() < 2) return false;
    const auto step_ns = truth.frames[1].stamp_ns - truth.frames[0].stamp_ns;
    for (std::size_t i = 1; i < truth.frames.size(); ++i) {
      const auto d = truth.frames[i].stamp_ns - truth.frames[i - 1].stamp_ns;
      if (truth.frames[i].person_id != truth.frames[0].person_id || std::llabs(d - step_ns) > 1'000'000) return false;
    }
    return true;
  };
  if (evenly()) {
    std::ofstream bvh(std::filesystem::path(dir) / "truth.bvh");
    playback::write_position_bvh(truth.frames, 1e-9 * static_cast<double>(truth.frames[1].stamp_ns - truth.frames[0].stamp_ns), 100.0,
                                 bvh);
    if (!bvh.flush()) throw std::runtime_error("error writing truth.bvh");
    files["truth.bvh"] = truth.frames.size();
    files["truth.bvh first frame s"] = 1e-9 * static_cast<double>(truth.frames.front().stamp_ns);
  } else {
    files["truth.bvh"] = "not written: not one person from start to end at a steady rate";
  }
  if (!phases.flush()) throw std::runtime_error("error writing phases.csv");
  files["phases.csv"] = truth.frames.size();
  return {sim.duration(), files};
}

HandAtToolSummary write_hand_at_tool(const SimConfig& cfg, const std::string& out, const HandAtToolOptions& o,
                                     const SimProgress& progress) {
  Simulation sim(cfg);
  recording::BagWriter bag(out);
  bag.write_metadata("source", {{"source", "skelgraph sim hand-at-tool"}, {"scenario", cfg.scenario.name},
                                {"seed", std::to_string(cfg.scenario.seed)}});
  for (const auto& s : cfg.sensors) {
    bag.write(runtime::topics::kCalibration.name, skeleton::to_msg(s.true_pose()), static_cast<std::uint64_t>(cfg.epoch_ns),
              static_cast<std::uint64_t>(cfg.epoch_ns));
  }
  cv::RNG rng(cfg.scenario.seed + 17);
  const Eigen::Vector3d phase(rng.uniform(0.0, 2 * M_PI), rng.uniform(0.0, 2 * M_PI), rng.uniform(0.0, 2 * M_PI));
  HandAtToolSummary r;
  for (double t = 5.0;; t += 5.0) {
    for (auto& e : sim.advance(t)) {
      // Logged when the world clock says (a recorder's clock); sensors stamp on their own.
      const auto stamp = static_cast<std::uint64_t>(cfg.epoch_ns + static_cast<std::int64_t>(e.t * 1e9));
      if (e.kind == SimEvent::Kind::Raw) {
        bag.write(runtime::topics::kSkeletonRaw.name, skeleton::to_msg(e.skeleton), stamp, stamp);
        ++r.raw_skeletons;
      } else if (e.kind == SimEvent::Kind::Truth) {
        bag.write(runtime::topics::kSkeletonTruth.name, skeleton::to_msg(e.skeleton), stamp, stamp);
        if (e.actor != sim.scenario().at(e.t).actors.front().person_id) continue;
        const auto& hand = e.skeleton[skeleton::JointId::RightHand].position;
        const auto& elbow = e.skeleton[skeleton::JointId::RightElbow].position;
        const Eigen::Vector3d touch = hand + 0.01 * o.contact_cm * (hand - elbow).normalized();
        // The robot's absolute error: smooth over the workspace (the same at the same place), sd tool_noise_mm.
        const Eigen::Vector3d err(std::sin(7 * touch.x() + phase.x()), std::sin(7 * touch.y() + phase.y()),
                                  std::sin(7 * touch.z() + phase.z()));
        const Eigen::Vector3d tool = touch + 1e-3 * o.tool_noise_mm * std::sqrt(2.0) * err;
        msg::RobotState st;
        st.robot_id("robot1");
        st.model("UR5e");
        st.stamp_ns(e.skeleton.stamp_ns);
        st.tool_position().x(tool.x());
        st.tool_position().y(tool.y());
        st.tool_position().z(tool.z());
        bag.write(runtime::topics::kRobotState.name, st, stamp, stamp);
        ++r.robot_states;
      }
    }
    if (progress) progress(std::min(t, sim.duration()), sim.duration());
    if (sim.finished()) break;
  }
  bag.close();
  r.duration_s = sim.duration();
  return r;
}

}  // namespace skelgraph::sim
