#include "skelgraph/depth_tracker/depth_tracker_component.hpp"

#include <chrono>
#include <sstream>

#include <spdlog/spdlog.h>

#include "skelgraph/depth/depth_msg.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::depth_tracker {

runtime::ComponentInfo DepthTrackerComponent::describe() {
  runtime::ComponentInfo info{"depth_tracker",
                              "Open skeleton tracking from depth: skelgraph/depth (+ each sensor's pose on "
                              "skelgraph/calibration) to skelgraph/skeleton/raw",
                              {}};
  const TrackerOptions d;
  info.params.add_double("voxel_m", d.voxel_m, "the person's points are thinned to one per cube of this side", 0.005, 0.2)
      .add_int("iterations", d.iterations, "model-fitting steps per frame", 1, 100)
      .add_double("floor_margin_m", d.floor_margin_m, "points this close above the floor are floor", 0.0, 0.5)
      .add_double("tracked_support", d.tracked_support, "points on a joint's segments for confidence 1", 0.0, 1000.0)
      .add_double("lost_after_s", d.lost_after_s, "a person not seen this long is dropped", 0.05, 60.0)
      .add_bool("assume_level", false,
                "track sensors with no pose on skelgraph/calibration as level, sensor_height above the floor "
                "(off: wait for their pose)")
      .add_double("sensor_height", 1.2, "with assume_level: the sensors' height above the floor, m", 0.1, 5.0)
      .add_bool("merge", false,
                "fit one model to every calibrated sensor's points at once and publish it as one sensor (world frame)")
      .add_string("merged_id", "merged", "with merge: the sensor_id of the merged skeletons");
  return info;
}

namespace {
TrackerOptions options_from(const runtime::Params& p) {
  TrackerOptions o;
  o.voxel_m = p.get<double>("voxel_m");
  o.iterations = static_cast<int>(p.get<std::int64_t>("iterations"));
  o.floor_margin_m = p.get<double>("floor_margin_m");
  o.tracked_support = p.get<double>("tracked_support");
  o.lost_after_s = p.get<double>("lost_after_s");
  return o;
}
}  // namespace

DepthTrackerComponent::DepthTrackerComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      options_(options_from(params)),
      merge_(params.get<bool>("merge")),
      merged_id_(params.get<std::string>("merged_id")),
      assume_level_(params.get<bool>("assume_level")),
      sensor_height_(params.get<double>("sensor_height")),
      raw_pub_(ctx, runtime::topics::kSkeletonRaw),
      frame_pub_(ctx, runtime::topics::kSensorFrame),
      pose_sub_(ctx, runtime::topics::kCalibration,
                [this](const msg::SensorPose& m, const runtime::SampleMeta&) {
                  const auto p = skeleton::from_msg(m);
                  if (p.frame_id != "world") return;  // the floor is known in the world frame only
                  std::lock_guard<std::mutex> lock(mutex_);
                  poses_[p.sensor_id] = p.pose;
                  auto it = sensors_.find(p.sensor_id);
                  if (it != sensors_.end()) {
                    it->second.tracker.set_pose(p.pose);
                    it->second.posed = true;
                  }
                }),
      pose_pub_(ctx, runtime::topics::kCalibration),
      depth_sub_(ctx, runtime::topics::kDepth, [this](const msg::DepthFrame& f, const runtime::SampleMeta& meta) {
        if (!merge_) return on_depth(f);
        try {
          on_depth_merged(depth::from_msg(f), meta.receive_ns);
        } catch (const std::invalid_argument& e) {
          ctx_.set_health(runtime::HealthState::Degraded, std::string("malformed depth frame: ") + e.what());
        }
      }) {
  DepthTracker probe(options_);  // checks the options before the graph starts
  if (merge_) {
    merged_ = std::make_unique<DepthTracker>(options_);
    skeleton::SensorPose p;  // the merged skeletons are in the world frame already
    p.sensor_id = merged_id_;
    p.method = "merged";
    pose_pub_.publish(skeleton::to_msg(p));
  }
}

void DepthTrackerComponent::on_depth_merged(depth::DepthImage image, std::int64_t receive_ns) {
  std::vector<skeleton::Skeleton> people;
  std::vector<std::uint32_t> gone;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (poses_.find(image.sensor_id) == poses_.end()) {
      if (sensors_[image.sensor_id].skipped++ == 0) {
        ctx_.set_health(runtime::HealthState::Degraded,
                        "waiting for the pose of " + image.sensor_id + " on skelgraph/calibration");
      }
      return;
    }
    ++sensors_[image.sensor_id].frames;
    const auto views = moments_.add(image.sensor_id, receive_ns, std::move(image));
    if (views.empty()) return;  // not the lead's frame
    // The lead's image with every other sensor's latest of the same moment (received within 40 ms).
    std::vector<depth::DepthImage> images;
    std::vector<Eigen::Isometry3d> poses;
    for (const auto& v : views) {
      images.push_back(*v.image);
      poses.push_back(poses_.at(v.sensor));
    }
    const auto t0 = std::chrono::steady_clock::now();
    people = merged_->track_merged(images, poses, merged_id_);
    gone = merged_->take_dropped();
    merged_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++merged_fits_;
    merged_skeletons_ += people.size();
    if (merged_fits_ == 1) ctx_.set_health(runtime::HealthState::Ok, "tracking (merged views)");
  }
  dispose(merged_id_, gone);
  std::int64_t stamp = 0;
  for (const auto& p : people) {
    stamp = p.stamp_ns;
    raw_pub_.publish(skeleton::to_msg(p));
  }
  msg::SensorFrame f;
  f.sensor_id(merged_id_);
  f.stamp_ns(stamp);
  f.frame_number(merged_fits_);
  f.people(static_cast<std::uint32_t>(people.size()));
  frame_pub_.publish(f);
}

void DepthTrackerComponent::on_depth(const msg::DepthFrame& frame) {
  depth::DepthImage image;
  try {
    image = depth::from_msg(frame);
  } catch (const std::invalid_argument& e) {
    ctx_.set_health(runtime::HealthState::Degraded, std::string("malformed depth frame: ") + e.what());
    return;
  }
  std::vector<skeleton::Skeleton> people;
  std::vector<std::uint32_t> gone;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = sensors_.find(image.sensor_id);
    if (it == sensors_.end()) {
      it = sensors_.emplace(image.sensor_id, Sensor{DepthTracker(options_)}).first;
      auto pose = poses_.find(image.sensor_id);
      if (pose != poses_.end()) {
        it->second.tracker.set_pose(pose->second);
        it->second.posed = true;
      } else if (assume_level_) {
        Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
        level.translation() = Eigen::Vector3d(0.0, sensor_height_, 0.0);
        it->second.tracker.set_pose(level);
      }
    }
    auto& s = it->second;
    if (!s.posed && !assume_level_) {
      if (s.skipped++ == 0) {
        ctx_.set_health(runtime::HealthState::Degraded,
                        "waiting for the pose of " + image.sensor_id + " on skelgraph/calibration");
      }
      return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    people = s.tracker.track(image);
    gone = s.tracker.take_dropped();
    s.track_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++s.frames;
    s.skeletons += people.size();
    if (s.frames == 1) ctx_.set_health(runtime::HealthState::Ok, "tracking");
  }
  dispose(image.sensor_id, gone);
  for (const auto& p : people) raw_pub_.publish(skeleton::to_msg(p));
  msg::SensorFrame f;
  f.sensor_id(image.sensor_id);
  f.stamp_ns(image.stamp_ns);
  f.frame_number(image.frame_number);
  f.people(static_cast<std::uint32_t>(people.size()));
  frame_pub_.publish(f);
}

// People the tracker forgot: their raw instances are disposed, so readers know at once.
void DepthTrackerComponent::dispose(const std::string& sensor, const std::vector<std::uint32_t>& people) {
  for (const auto id : people) {
    msg::Skeleton key;
    key.sensor_id(sensor);
    key.person_id(id);
    raw_pub_.dispose(key);
  }
}

std::string DepthTrackerComponent::summary() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream os;
  bool first = true;
  for (const auto& [id, s] : sensors_) {
    os << (first ? "" : "; ") << id << ": " << s.frames << " images, " << s.skeletons << " skeletons";
    if (s.frames > 0) os << ", " << static_cast<int>(1e3 * s.track_s / static_cast<double>(s.frames) * 10) / 10.0 << " ms each";
    if (s.skipped > 0) os << ", " << s.skipped << " waited for a pose";
    first = false;
  }
  if (first) os << "no depth images yet";
  if (merge_) {
    os << "; merged: " << merged_fits_ << " fits, " << merged_skeletons_ << " skeletons";
    if (merged_fits_ > 0) os << ", " << static_cast<int>(1e4 * merged_s_ / static_cast<double>(merged_fits_)) / 10.0 << " ms each";
  }
  return os.str();
}

nlohmann::json DepthTrackerComponent::details() const {
  std::lock_guard<std::mutex> lock(mutex_);
  nlohmann::json sensors = nlohmann::json::object();
  for (const auto& [id, s] : sensors_) {
    sensors[id] = {{"images", s.frames},
                   {"skeletons", s.skeletons},
                   {"skipped_without_pose", s.skipped},
                   {"people_started", s.tracker.stats().initialisations},
                   {"track_ms_per_image", s.frames ? 1e3 * s.track_s / static_cast<double>(s.frames) : 0.0}};
  }
  nlohmann::json out = {{"sensors", sensors}};
  if (merge_) {
    out["merged"] = {{"id", merged_id_}, {"fits", merged_fits_}, {"skeletons", merged_skeletons_},
                     {"fit_ms", merged_fits_ ? 1e3 * merged_s_ / static_cast<double>(merged_fits_) : 0.0}};
  }
  return out;
}

}  // namespace skelgraph::depth_tracker

SKELGRAPH_REGISTER_COMPONENT(depth_tracker, skelgraph::depth_tracker::DepthTrackerComponent)
