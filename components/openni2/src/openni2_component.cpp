#include "skelgraph/openni2/openni2_component.hpp"

#include <algorithm>
#include <sstream>
#include <utility>

#include <spdlog/spdlog.h>

#include "skelgraph/depth/depth_msg.hpp"

namespace skelgraph::openni2 {

runtime::ComponentInfo OpenNI2Component::describe() {
  runtime::ComponentInfo info{"openni2",
                              "OpenNI2 depth device (Kinect, Xtion, Carmine), .oni recording or the Dummy test "
                              "device, published on skelgraph/depth; records sync sessions to .oni",
                              {}};
  info.params
      .add_string("uri", "Dummy",
                  "device URI, \"any\" for the first device, \"Dummy\" for OpenNI2's test device, or an .oni file")
      .add_string("sensor_id", "depth1", "the sensor's name on skelgraph/depth")
      .add_double("speed", 1.0, "recordings: 1 real time, 2 twice as fast, 0 as fast as possible", 0.0, 100.0)
      .add_bool("repeat", false, "recordings: start again at the end")
      .add_bool("paused", false, "recordings: start paused (then `skelgraph play step|resume`)")
      .add_string("record_directory", "",
                  "record each sync session (START..STOP) of a device to DIR/<sensor_id>_session<N>.oni (empty: off)")
      .add_int("width", 0, "devices: depth image width to ask for (0: the device's default)", 0, 4096)
      .add_int("height", 0, "devices: depth image height to ask for (0: the device's default)", 0, 4096)
      .add_int("fps", 0, "devices: frame rate to ask for (0: the device's default)", 0, 1000)
      .add_bool("mend_recordings", true,
                "make the recordings playable by OpenNI2's player when the device has no cropping property (Dummy)");
  return info;
}

OpenNI2Component::OpenNI2Component(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx), depth_pub_(ctx, runtime::topics::kDepth) {
  options_.uri = params.get<std::string>("uri");
  options_.sensor_id = params.get<std::string>("sensor_id");
  options_.speed = params.get<double>("speed");
  options_.repeat = params.get<bool>("repeat");
  options_.mend_recordings = params.get<bool>("mend_recordings");
  options_.width = static_cast<int>(params.get<std::int64_t>("width"));
  options_.height = static_cast<int>(params.get<std::int64_t>("height"));
  options_.fps = static_cast<int>(params.get<std::int64_t>("fps"));
  options_.clock = ctx.clock_ptr();
  record_dir_ = params.get<std::string>("record_directory");
  source_ = std::make_unique<OniSource>(options_);
  finite_ = source_->is_file() && !options_.repeat;
  description_ = source_->description();
  if (source_->is_file()) {
    player_ = std::make_unique<runtime::PlayerLink>(
        ctx, runtime::PlayGate(options_.speed, params.get<bool>("paused")),
        [this] {
          std::lock_guard<std::mutex> lock(mutex_);
          runtime::PlayerLink::Progress p;
          p.frames = published_;
          p.frame_count = source_->frame_count();
          p.at_end = finished_;
          return p;
        },
        /*can_seek=*/false);
  } else if (params.get<bool>("paused")) {
    throw std::invalid_argument("openni2: paused is for recordings, not devices");
  }
  if (!record_dir_.empty()) {
    if (source_->is_file()) throw std::invalid_argument("openni2: record_directory is for devices, not recordings");
    sync_sub_ = std::make_unique<runtime::Subscription<msg::SyncCommand>>(
        ctx, runtime::topics::kSync, [this](const msg::SyncCommand& c, const runtime::SampleMeta&) { on_sync(c, false); });
    session_sub_ = std::make_unique<runtime::Subscription<msg::SyncCommand>>(
        ctx, runtime::topics::kSyncSession,
        [this](const msg::SyncCommand& c, const runtime::SampleMeta&) { on_sync(c, true); });
  }
}

OpenNI2Component::~OpenNI2Component() { on_shutdown(); }

void OpenNI2Component::on_start() {
  if (!source_->intrinsics_from_device()) {
    ctx_.set_health(runtime::HealthState::Ok,
                    "the device reports no field of view: Kinect-like intrinsics assumed");
  }
  if (player_) player_->publish_state();
  thread_ = std::thread([this] { run(); });
}

void OpenNI2Component::on_shutdown() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void OpenNI2Component::on_sync(const msg::SyncCommand& cmd, bool session_topic) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (cmd.kind() == msg::SYNC_START && cmd.session_id() != last_stopped_) {
    want_session_ = cmd.session_id();
  } else if (cmd.kind() == msg::SYNC_STOP && want_session_ && *want_session_ == cmd.session_id()) {
    want_session_.reset();
    last_stopped_ = cmd.session_id();
  } else if (cmd.kind() == msg::SYNC_STOP && session_topic) {
    last_stopped_ = cmd.session_id();  // a late joiner: that session is over
  }
}

void OpenNI2Component::run() {
  try {
    while (!stop_) {
      // Start or stop an .oni recording as the sync sessions say (on this thread: OpenNI calls stay on one thread).
      if (!record_dir_.empty()) {
        std::optional<std::uint32_t> want;
        std::uint32_t now = 0;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          want = want_session_;
          now = recording_session_;
        }
        if (now != 0 && (!want || *want != now)) {
          const auto frames = source_->stop_recording();
          std::lock_guard<std::mutex> lock(mutex_);
          files_.push_back(record_dir_ + "/" + options_.sensor_id + "_session" + std::to_string(now) + ".oni");
          files_frames_ += frames;
          recording_session_ = 0;
          now = 0;
        }
        if (want && now == 0) {
          source_->start_recording(record_dir_ + "/" + options_.sensor_id + "_session" + std::to_string(*want) + ".oni");
          std::lock_guard<std::mutex> lock(mutex_);
          recording_session_ = *want;
        }
      }
      bool stepped = false;
      if (player_) {
        // A player: wait while paused; steps come without waiting; a new speed
        // or a resume paces afresh from the next frame.
        const auto [deliver, repace, stepping, speed] = player_->turn();
        stepped = stepping;
        if (!deliver) {
          player_->wait_for_request(std::chrono::milliseconds(5));
          continue;
        }
        if (repace || stepping) source_->set_speed(speed);
      }
      auto image = source_->next(std::chrono::milliseconds(100));
      if (image) {
        depth_pub_.publish(depth::to_msg(std::move(*image)));
        {
          std::lock_guard<std::mutex> lock(mutex_);
          ++published_;
        }
        if (player_) player_->delivered(stepped);
      } else if (source_->at_end()) {
        finished_ = true;
        if (const auto lost = source_->frames_never_delivered()) {
          ctx_.set_health(runtime::HealthState::Degraded, "end of recording: OpenNI2's player never delivered " +
                                                              std::to_string(lost) + " of its " +
                                                              std::to_string(source_->frame_count()) + " frames");
          spdlog::warn("{}: OpenNI2's player never delivered {} frame(s) of the recording", ctx_.name(), lost);
        } else {
          ctx_.set_health(runtime::HealthState::Ok, "end of recording");
        }
        if (player_) player_->at_end();
        break;
      }
    }
    if (source_->recording()) {
      const auto frames = source_->stop_recording();
      std::lock_guard<std::mutex> lock(mutex_);
      files_.push_back(record_dir_ + "/" + options_.sensor_id + "_session" + std::to_string(recording_session_) + ".oni");
      files_frames_ += frames;
      recording_session_ = 0;
    }
  } catch (const std::exception& e) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = e.what();
    }
    ctx_.set_health(runtime::HealthState::Error, e.what());
    finished_ = true;
  }
}

std::string OpenNI2Component::summary() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream os;
  os << description_ << ": " << published_ << " depth frames";
  if (!files_.empty()) os << ", " << files_.size() << " .oni recording(s)";
  if (!error_.empty()) os << "; error: " << error_;
  return os.str();
}

nlohmann::json OpenNI2Component::details() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto& k = source_->intrinsics();
  return {{"uri", options_.uri},
          {"sensor_id", options_.sensor_id},
          {"device", description_},
          {"width", k.width},
          {"height", k.height},
          {"fx", k.fx},
          {"fy", k.fy},
          {"intrinsics_from_device", source_->intrinsics_from_device()},
          {"frames_in_recording", source_->frame_count()},
          {"published", published_},
          {"frames_never_delivered", source_->frames_never_delivered()},
          {"paused", player_ ? player_->with_gate([](runtime::PlayGate& g) { return g.paused(); }) : false},
          {"speed", player_ ? player_->with_gate([](runtime::PlayGate& g) { return g.speed(); }) : 0.0},
          {"recordings", files_},
          {"recorded_frames", files_frames_},
          {"error", error_}};
}

}  // namespace skelgraph::openni2

SKELGRAPH_REGISTER_COMPONENT(openni2, skelgraph::openni2::OpenNI2Component)
