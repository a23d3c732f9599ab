#include "skelgraph/depth_tracker/sim_depth.hpp"

#include "skelgraph/depth_tracker/frame_matcher.hpp"

#include <chrono>
#include <cmath>
#include <optional>

namespace skelgraph::depth_tracker {

SimDepthResult track_simulated_depth(sim::SimConfig config, const SimDepthOptions& options) {
  config.emit_frames = true;
  sim::Simulation sim(config);
  std::vector<sim::DepthRenderer> renderers;
  std::vector<DepthTracker> trackers;
  std::vector<sim::Rng> rngs;
  const sim::Rng base(config.scenario.seed);
  for (std::size_t i = 0; i < config.sensors.size(); ++i) {
    renderers.emplace_back(config.sensors[i], options.intrinsics, options.noise);
    trackers.emplace_back(options.tracker);
    trackers.back().set_pose(config.sensors[i].world_from_sensor());
    rngs.push_back(base.fork(0xde97000 + i));
  }
  using Clock = std::chrono::steady_clock;
  SimDepthResult r;
  DepthTracker merged_tracker(options.tracker);
  std::vector<Eigen::Isometry3d> poses;
  for (const auto& s : config.sensors) poses.push_back(s.world_from_sensor());
  FrameMatcher<std::size_t> moments(40'000'000, std::size_t{0});  // the first sensor's frames lead
  for (auto& e : sim.advance(sim.duration() + 1.0)) {
    const auto t_ns = config.epoch_ns + static_cast<std::int64_t>(std::llround(e.t * 1e9));
    if (e.kind == sim::SimEvent::Kind::Truth) {
      r.events.push_back({eval::TimedSkeleton::Kind::Truth, t_ns, std::move(e.skeleton)});
      continue;
    }
    if (e.kind != sim::SimEvent::Kind::Frame) continue;  // the simulated trackers' skeletons are not used here
    const auto t0 = Clock::now();
    auto image = renderers[e.sensor].render(sim.truth_at(e.t), sim.scenario().at(e.t).obstacles, rngs[e.sensor],
                                            config.scenario.height, options.girth);
    image.stamp_ns = e.skeleton.stamp_ns;
    image.frame_number = e.skeleton.frame_number;
    const auto t1 = Clock::now();
    if (!options.merged) {
      for (auto& s : trackers[e.sensor].track(image)) r.events.push_back({eval::TimedSkeleton::Kind::Raw, t_ns, std::move(s)});
    } else {
      const auto views = moments.add(e.sensor, t_ns, std::move(image));
      if (!views.empty()) {
        std::vector<depth::DepthImage> images;
        std::vector<Eigen::Isometry3d> view_poses;
        for (const auto& v : views) {
          images.push_back(*v.image);
          view_poses.push_back(poses[v.sensor]);
        }
        for (auto& s : merged_tracker.track_merged(images, view_poses)) {
          r.events.push_back({eval::TimedSkeleton::Kind::Raw, t_ns, std::move(s)});
        }
      }
    }
    const auto t2 = Clock::now();
    r.render_s += std::chrono::duration<double>(t1 - t0).count();
    r.track_s += std::chrono::duration<double>(t2 - t1).count();
    ++r.frames;
  }
  return r;
}

}  // namespace skelgraph::depth_tracker
