#include "skelgraph/depth/cloud_component.hpp"

#include <chrono>
#include <sstream>

#include "skelgraph/depth/depth_msg.hpp"
#include "skelgraph/depth_tracker/tracker.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::depth {

runtime::ComponentInfo CloudComponent::describe() {
  runtime::ComponentInfo info{"cloud",
                              "Point clouds for viewers: each sensor's foreground from skelgraph/depth, in the world "
                              "frame (poses from skelgraph/calibration), merged and thinned, on skelgraph/cloud",
                              {}};
  info.params.add_double("rate_hz", 10.0, "clouds per second", 0.1, 60.0)
      .add_double("voxel_m", 0.03, "thinned to one point per cube of this side", 0.005, 1.0)
      .add_int("stride", 2, "every stride-th pixel in each direction", 1, 16)
      .add_bool("merge", true, "one cloud of every sensor (\"merged\", world frame); off: each sensor's own")
      .add_string("select", "people", "which points: people (person-shaped regions above the floor, as the depth "
                  "tracker finds them), foreground (what differs from the learnt static scene), all (above the floor)",
                  {"people", "foreground", "all"})
      .add_double("floor_margin_m", 0.05, "with a pose: points this close above the floor are left out", 0.0, 1.0);
  return info;
}

CloudComponent::CloudComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      voxel_m_(params.get<double>("voxel_m")),
      period_s_(1.0 / params.get<double>("rate_hz")),
      floor_margin_m_(params.get<double>("floor_margin_m")),
      stride_(static_cast<int>(params.get<std::int64_t>("stride"))),
      merge_(params.get<bool>("merge")),
      select_(params.get<std::string>("select")),
      pub_(ctx, runtime::topics::kCloud),
      pose_sub_(ctx, runtime::topics::kCalibration,
                [this](const msg::SensorPose& m, const runtime::SampleMeta&) {
                  const auto p = skeleton::from_msg(m);
                  if (p.frame_id != "world") return;
                  std::lock_guard<std::mutex> lock(mutex_);
                  poses_[p.sensor_id] = p.pose;
                }),
      depth_sub_(ctx, runtime::topics::kDepth,
                 [this](const msg::DepthFrame& f, const runtime::SampleMeta& meta) { on_depth(f, meta.receive_ns); }) {}

void CloudComponent::on_start() {
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(static_cast<std::int64_t>(period_s_ * 1e9)),
                                 [this] { publish(); }, true);
}

void CloudComponent::on_depth(const msg::DepthFrame& frame, std::int64_t receive_ns) {
  DepthImage image;
  try {
    image = from_msg(frame);
  } catch (const std::invalid_argument& e) {
    ctx_.set_health(runtime::HealthState::Degraded, std::string("malformed depth frame: ") + e.what());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  auto& s = sensors_[image.sensor_id];
  ++s.images;
  const auto pose = poses_.find(image.sensor_id);
  s.posed = pose != poses_.end();
  Points pts;
  if (select_ == "people") {
    if (!s.posed) return;  // the floor is known in the world frame only
    for (auto& person : depth_tracker::find_people(image, pose->second)) {
      pts.insert(pts.end(), person.points.begin(), person.points.end());
    }
    s.world = voxel_downsample(pts, voxel_m_);
    s.stamp_ns = image.stamp_ns;
    s.frame_number = image.frame_number;
    s.received_ns = receive_ns;
    return;
  }
  std::vector<std::uint8_t> mask(image.mm.size(), 1);
  if (select_ == "foreground") {
    if (s.background.ready()) mask = s.background.foreground(image);
    s.background.learn(image);
  }
  pts = to_points(image, mask, stride_);
  if (s.posed) {
    pts = transformed(pts, pose->second);
    pts.erase(std::remove_if(pts.begin(), pts.end(), [&](const Eigen::Vector3f& p) { return p.y() < floor_margin_m_; }),
              pts.end());
  }
  s.world = voxel_downsample(pts, voxel_m_);
  s.stamp_ns = image.stamp_ns;
  s.frame_number = image.frame_number;
  s.received_ns = receive_ns;
}

void CloudComponent::publish() {
  const auto now = ctx_.clock().now_ns();
  const auto fresh = static_cast<std::int64_t>(std::max(0.2, 2 * period_s_) * 1e9);
  std::vector<msg::PointCloud> out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto fill = [](msg::PointCloud& m, const Points& pts) {
      std::vector<float> xyz;
      xyz.reserve(pts.size() * 3);
      for (const auto& p : pts) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
      m.xyz(std::move(xyz));
    };
    if (merge_) {
      Points all;
      std::int64_t stamp = 0;
      for (const auto& [id, s] : sensors_) {
        if (!s.posed || now - s.received_ns > fresh) continue;
        all.insert(all.end(), s.world.begin(), s.world.end());
        stamp = std::max(stamp, s.stamp_ns);
      }
      if (stamp == 0) return;
      msg::PointCloud m;
      m.source("merged");
      m.frame_id("world");
      m.stamp_ns(stamp);
      m.frame_number(published_ + 1);
      m.voxel_m(voxel_m_);
      fill(m, voxel_downsample(all, voxel_m_));
      out.push_back(std::move(m));
    } else {
      for (const auto& [id, s] : sensors_) {
        if (now - s.received_ns > fresh) continue;
        msg::PointCloud m;
        m.source(id.substr(0, 64));
        m.frame_id(s.posed ? "world" : id.substr(0, 64));
        m.stamp_ns(s.stamp_ns);
        m.frame_number(s.frame_number);
        m.voxel_m(voxel_m_);
        fill(m, s.world);
        out.push_back(std::move(m));
      }
    }
  }
  for (const auto& m : out) {
    pub_.publish(m);
    std::lock_guard<std::mutex> lock(mutex_);
    ++published_;
    last_points_ = m.xyz().size() / 3;
  }
}

std::string CloudComponent::summary() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream os;
  os << published_ << " clouds from " << sensors_.size() << " sensor(s), last " << last_points_ << " points";
  return os.str();
}

nlohmann::json CloudComponent::details() const {
  std::lock_guard<std::mutex> lock(mutex_);
  nlohmann::json sensors = nlohmann::json::object();
  for (const auto& [id, s] : sensors_) sensors[id] = {{"images", s.images}, {"posed", s.posed}, {"points", s.world.size()}};
  return {{"published", published_}, {"last_points", last_points_}, {"sensors", sensors}};
}

}  // namespace skelgraph::depth

SKELGRAPH_REGISTER_COMPONENT(cloud, skelgraph::depth::CloudComponent)
