#include "skelgraph/depth/depth_files_component.hpp"

#include <algorithm>
#include <sstream>

#include "skelgraph/depth/depth_msg.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::depth {

runtime::ComponentInfo DepthFilesComponent::describe() {
  runtime::ComponentInfo info{"depth_files",
                              "A folder of depth image files (16-bit PGM or PNG, raw uint16) played on skelgraph/depth as a "
                              "depth camera would publish it; a player (pause, step, speed, seek)",
                              {}};
  info.params.add_string("directory", "", "the folder of depth images (every file but .txt/.yaml/.json, in name order)")
      .add_string("pattern", "", "the image files' names, a regex the whole name matches (default: every file but documents and licences)")
      .add_string("format", "auto", "image files: auto (by extension; anything but .pgm/.png is raw), pgm, png, raw",
                  {"auto", "pgm", "png", "raw"})
      .add_int("width", 0, "raw: the image width (others: checked when given)", 0, 16384)
      .add_int("height", 0, "raw: the image height (others: checked when given)", 0, 16384)
      .add_string("byte_order", "auto", "auto (PGM big-endian as its standard says, raw little-endian), little or big",
                  {"auto", "little", "big"})
      .add_string("intrinsics", "", "intrinsics YAML (skelgraph calib intrinsics); else fx/fy/cx/cy, else Kinect-like")
      .add_double("fx", 0.0, "focal length in pixels (0: from the file or Kinect-like)", 0.0, 100000.0)
      .add_double("fy", 0.0, "focal length in pixels (0: = fx)", 0.0, 100000.0)
      .add_double("cx", -1.0, "principal point (-1: the image centre)", -1.0, 100000.0)
      .add_double("cy", -1.0, "principal point (-1: the image centre)", -1.0, 100000.0)
      .add_string("timestamps", "", "a file with one time per image (seconds), in name order; else `rate`")
      .add_double("rate", 30.0, "frames per second without a timestamps file", 0.001, 1000.0)
      .add_double("speed", 1.0, "1 as the times say, 2 twice as fast, 0 as fast as possible", 0.0, 1000.0)
      .add_bool("paused", false, "start paused (then `skelgraph player step|resume`)")
      .add_bool("loop", false, "start again at the end")
      .add_bool("hold_at_end", false, "stay at the end (a seek plays on from there) instead of finishing")
      .add_double("wait_s", 5.0, "wait this long at most for a reader of skelgraph/depth before the first frame", 0.0, 600.0)
      .add_string("sensor_id", "depth1", "the sensor's name on skelgraph/depth");
  return info;
}

DepthFilesComponent::DepthFilesComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx), depth_pub_(ctx, runtime::topics::kDepth) {
  DepthFilesOptions o;
  const auto dir = params.get<std::string>("directory");
  if (dir.empty()) throw std::invalid_argument("depth_files: directory is required");
  o.format = params.get<std::string>("format");
  o.pattern = params.get<std::string>("pattern");
  o.width = static_cast<int>(params.get<std::int64_t>("width"));
  o.height = static_cast<int>(params.get<std::int64_t>("height"));
  o.byte_order = params.get<std::string>("byte_order");
  o.intrinsics_file = params.get<std::string>("intrinsics");
  o.timestamps = params.get<std::string>("timestamps");
  o.rate_hz = params.get<double>("rate");
  o.sensor_id = params.get<std::string>("sensor_id");
  const double fx = params.get<double>("fx");
  if (fx > 0 && !o.intrinsics_file.empty()) throw std::invalid_argument("depth_files: give intrinsics or fx/fy/cx/cy, not both");
  loop_ = params.get<bool>("loop");
  hold_at_end_ = params.get<bool>("hold_at_end");
  wait_s_ = params.get<double>("wait_s");
  folder_ = std::make_unique<DepthFolder>(dir, o);
  folder_->check_raw_sizes();
  // The first image now: bad files and sizes are refused before the graph starts.
  const auto first = folder_->read(0);
  if (fx > 0) {
    DepthFilesOptions with = folder_->options();
    with.intrinsics.width = first.width();
    with.intrinsics.height = first.height();
    with.intrinsics.fx = fx;
    with.intrinsics.fy = params.get<double>("fy") > 0 ? params.get<double>("fy") : fx;
    with.intrinsics.cx = params.get<double>("cx") >= 0 ? params.get<double>("cx") : (first.width() - 1) / 2.0;
    with.intrinsics.cy = params.get<double>("cy") >= 0 ? params.get<double>("cy") : (first.height() - 1) / 2.0;
    with.intrinsics_given = true;
    with.intrinsics_file.clear();
    folder_ = std::make_unique<DepthFolder>(dir, with);
  }
  player_ = std::make_unique<runtime::PlayerLink>(
      ctx, runtime::PlayGate(params.get<double>("speed"), params.get<bool>("paused")),
      [this] {
        std::lock_guard<std::mutex> lock(mutex_);
        runtime::PlayerLink::Progress p;
        p.frames = published_;
        p.frame_count = static_cast<std::int64_t>(folder_->size());
        p.at_end = finished_ || position_ >= folder_->size();
        p.position_s = 1e-9 * static_cast<double>(folder_->offset_ns(std::min(position_, folder_->size() - 1)));
        p.duration_s = folder_->duration_s();
        return p;
      },
      /*can_seek=*/true);
}

DepthFilesComponent::~DepthFilesComponent() { on_shutdown(); }

void DepthFilesComponent::on_start() {
  player_->publish_state();
  thread_ = std::thread([this] { run(); });
}

void DepthFilesComponent::on_shutdown() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void DepthFilesComponent::run() {
  try {
    // Frames published before a reader matched are lost (best effort): wait
    // for one first, and 0.5 s more (our writer matches a reader before that
    // reader has matched the writer).
    const auto t0 = ctx_.clock().monotonic_ns();
    std::int64_t matched_at = 0;
    while (!stop_) {
      const auto now = ctx_.clock().monotonic_ns();
      if (matched_at == 0 && depth_pub_.matched() > 0) matched_at = now;
      if ((matched_at != 0 && now - matched_at >= 500'000'000) || now - t0 >= static_cast<std::int64_t>(wait_s_ * 1e9)) break;
      player_->wait_for_request(std::chrono::milliseconds(20));
    }
    std::int64_t pace_mono = 0, pace_offset = 0;
    std::size_t i = 0;
    while (!stop_) {
      if (const auto seek = player_->with_gate([](runtime::PlayGate& g) { return g.take_seek(); })) {
        const auto target = static_cast<std::int64_t>(*seek * 1e9);
        i = 0;
        while (i + 1 < folder_->size() && folder_->offset_ns(i + 1) <= target) ++i;
        pace_mono = 0;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          position_ = i;
        }
        player_->sought();
      }
      if (i >= folder_->size()) {
        if (loop_) {
          i = 0;
          pace_mono = 0;
          std::lock_guard<std::mutex> lock(mutex_);
          ++loops_;
          position_ = 0;
          continue;
        }
        player_->at_end();
        if (!hold_at_end_) break;
        player_->wait_for_request(std::chrono::milliseconds(50));
        continue;
      }
      const auto [deliver, repace, stepping, speed] = player_->turn();
      if (!deliver) {
        player_->wait_for_request(std::chrono::milliseconds(50));
        continue;
      }
      const auto now = ctx_.clock().monotonic_ns();
      if (repace || pace_mono == 0) {
        pace_mono = now;
        pace_offset = folder_->offset_ns(i);
      }
      if (!stepping && speed > 0.0) {
        const auto due = pace_mono + static_cast<std::int64_t>(static_cast<double>(folder_->offset_ns(i) - pace_offset) / speed);
        if (now < due) {
          player_->wait_for_request(std::chrono::nanoseconds(std::min<std::int64_t>(due - now, 50'000'000)));
          continue;
        }
      }
      auto image = folder_->read(i);
      image.stamp_ns = ctx_.clock().now_ns();
      depth_pub_.publish(to_msg(std::move(image)));
      ++i;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++published_;
        position_ = i;
      }
      player_->delivered(stepping);
    }
    finished_ = true;
    ctx_.set_health(runtime::HealthState::Ok, "end of the images");
  } catch (const std::exception& e) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = e.what();
    }
    ctx_.set_health(runtime::HealthState::Error, e.what());
    finished_ = true;
  }
}

std::string DepthFilesComponent::summary() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream os;
  os << folder_->size() << " depth images, " << published_ << " published";
  if (loops_ > 0) os << " (" << loops_ << " loops)";
  if (!error_.empty()) os << "; error: " << error_;
  return os.str();
}

nlohmann::json DepthFilesComponent::details() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto& k = folder_->options().intrinsics;
  return {{"images", folder_->size()},
          {"duration_s", folder_->duration_s()},
          {"published", published_},
          {"loops", loops_},
          {"position", position_},
          {"intrinsics_given", folder_->options().intrinsics_given},
          {"fx", k.fx},
          {"sensor_id", folder_->options().sensor_id},
          {"error", error_}};
}

}  // namespace skelgraph::depth

SKELGRAPH_REGISTER_COMPONENT(depth_files, skelgraph::depth::DepthFilesComponent)
