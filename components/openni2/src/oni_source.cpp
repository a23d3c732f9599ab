#include "skelgraph/openni2/oni_source.hpp"

#include <OpenNI.h>

#include <cmath>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace skelgraph::openni2 {

namespace {


// OpenNI::initialize/shutdown are reference counted; one pair per source.
void initialize_openni() {
  if (openni::OpenNI::initialize() != openni::STATUS_OK) {
    throw std::runtime_error(std::string("OpenNI2 did not initialise: ") + openni::OpenNI::getExtendedError());
  }
}

std::string oni_error(const std::string& what) {
  const char* e = openni::OpenNI::getExtendedError();
  std::string msg = what;
  if (e != nullptr && *e != '\0') msg += ": " + std::string(e);
  return msg;
}

}  // namespace

struct OniSource::Impl {
  openni::Device device;
  openni::VideoStream depth;
  openni::VideoFrameRef frame;
  std::unique_ptr<openni::Recorder> recorder;
  std::string recording_path;
  bool depth_started = false, device_open = false;
};

OniSource::OniSource(OniOptions options) : opt_(std::move(options)) {
  if (!(opt_.speed >= 0) || !std::isfinite(opt_.speed)) throw std::invalid_argument("openni2: speed must be >= 0");
  initialize_openni();
  try {
    open_device();
  } catch (...) {
    close_device();
    openni::OpenNI::shutdown();
    throw;
  }
}

OniSource::~OniSource() {
  try {
    if (recording()) stop_recording();
  } catch (...) {
  }
  close_device();
  openni::OpenNI::shutdown();
}

void OniSource::open_device() {
  impl_ = std::make_unique<Impl>();
  const bool any = opt_.uri == "any";
  const bool looks_like_file = std::filesystem::path(opt_.uri).extension() == ".oni";
  if (looks_like_file && !std::filesystem::is_regular_file(opt_.uri)) {
    throw std::runtime_error("openni2: no recording '" + opt_.uri + "'");
  }
  if (impl_->device.open(any ? openni::ANY_DEVICE : opt_.uri.c_str()) != openni::STATUS_OK) {
    std::string known;
    openni::Array<openni::DeviceInfo> list;
    openni::OpenNI::enumerateDevices(&list);
    for (int i = 0; i < list.getSize(); ++i) known += std::string(known.empty() ? "" : ", ") + list[i].getUri();
    throw std::runtime_error(oni_error("openni2: cannot open '" + opt_.uri + "'") + " (devices connected: " +
                             (known.empty() ? "none" : known) + "; the test device is \"Dummy\")");
  }
  impl_->device_open = true;
  if (!impl_->device.hasSensor(openni::SENSOR_DEPTH)) {
    throw std::runtime_error("openni2: '" + opt_.uri + "' has no depth sensor");
  }
  if (impl_->depth.create(impl_->device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    throw std::runtime_error(oni_error("openni2: no depth stream on '" + opt_.uri + "'"));
  }
  if ((opt_.width > 0 || opt_.height > 0 || opt_.fps > 0) && !impl_->device.isFile()) choose_mode();
  const openni::VideoMode mode = impl_->depth.getVideoMode();
  if (mode.getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_1_MM && mode.getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_100_UM) {
    throw std::runtime_error("openni2: '" + opt_.uri + "' delivers depth in pixel format " +
                             std::to_string(static_cast<int>(mode.getPixelFormat())) + "; only millimetres (100) and 100 um (101) are supported");
  }
  fps_ = mode.getFps() > 0 ? mode.getFps() : 30.0;
  const float hfov = impl_->depth.getHorizontalFieldOfView(), vfov = impl_->depth.getVerticalFieldOfView();
  if (hfov > 0.1f && vfov > 0.1f) {
    intrinsics_ = depth::intrinsics_from_fov(mode.getResolutionX(), mode.getResolutionY(), hfov, vfov);
    intrinsics_from_device_ = true;
  } else {
    intrinsics_ = depth::kinect_intrinsics(mode.getResolutionX(), mode.getResolutionY());
    intrinsics_from_device_ = false;
  }
  if (auto* pc = impl_->device.getPlaybackControl()) {
    // Step mode: a frame per request, none dropped; pacing is ours (next()).
    pc->setSpeed(-1.0f);
    pc->setRepeatEnabled(false);
  }
  if (impl_->depth.start() != openni::STATUS_OK) {
    throw std::runtime_error(oni_error("openni2: depth stream on '" + opt_.uri + "' did not start"));
  }
  impl_->depth_started = true;
  if (auto* pc = impl_->device.getPlaybackControl()) frame_count_ = pc->getNumberOfFrames(impl_->depth);
  frames_this_pass_ = 0;
  waited_ms_ = 0;
  at_end_ = false;
}

void OniSource::choose_mode() {
  const auto matches = [&](const openni::VideoMode& m) {
    const bool depth_format = m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM ||
                              m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM;
    return depth_format && (opt_.width <= 0 || m.getResolutionX() == opt_.width) &&
           (opt_.height <= 0 || m.getResolutionY() == opt_.height) && (opt_.fps <= 0 || m.getFps() == opt_.fps);
  };
  const auto describe = [](const openni::VideoMode& m) {
    return std::to_string(m.getResolutionX()) + "x" + std::to_string(m.getResolutionY()) + "@" +
           std::to_string(m.getFps()) + (m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM ? " mm" : "");
  };
  if (matches(impl_->depth.getVideoMode())) return;  // already so
  const auto& modes = impl_->depth.getSensorInfo().getSupportedVideoModes();
  std::string offered;
  for (int i = 0; i < modes.getSize(); ++i) {
    if (matches(modes[i])) {
      if (impl_->depth.setVideoMode(modes[i]) != openni::STATUS_OK) {
        throw std::runtime_error(oni_error("openni2: '" + opt_.uri + "' refused depth mode " + describe(modes[i])));
      }
      return;
    }
    offered += (offered.empty() ? "" : ", ") + describe(modes[i]);
  }
  const std::string want = (opt_.width > 0 ? std::to_string(opt_.width) : "any") + "x" +
                           (opt_.height > 0 ? std::to_string(opt_.height) : "any") + "@" +
                           (opt_.fps > 0 ? std::to_string(opt_.fps) : "any");
  throw std::runtime_error("openni2: '" + opt_.uri + "' has no depth mode " + want + " (it offers: " +
                           (offered.empty() ? describe(impl_->depth.getVideoMode()) : offered) + ")");
}

void OniSource::close_device() {
  if (!impl_) return;
  if (impl_->depth_started) {
    impl_->depth.stop();
    // The Dummy driver's thread notices the stop only at its next 33 ms turn;
    // destroying the stream before that crashes it.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  impl_->frame.release();
  impl_->depth.destroy();
  if (impl_->device_open) impl_->device.close();
  impl_.reset();
}

bool OniSource::is_file() const { return impl_ && impl_->device.isFile(); }

std::string OniSource::description() const {
  if (!impl_) return opt_.uri + " (closed)";
  const auto& info = impl_->device.getDeviceInfo();
  std::string d = std::string(info.getUri()) + " (" + info.getVendor() + (*info.getName() ? " " : "") + info.getName() +
                  "), depth " + std::to_string(intrinsics_.width) + "x" + std::to_string(intrinsics_.height) + " at " +
                  std::to_string(static_cast<int>(fps_)) + " Hz";
  if (frame_count_ >= 0) d += ", " + std::to_string(frame_count_) + " frames";
  return d;
}

std::optional<depth::DepthImage> OniSource::next(std::chrono::milliseconds timeout) {
  if (!impl_ || at_end_) return std::nullopt;
  const bool file = is_file();
  if (file && frame_count_ >= 0 && frames_this_pass_ >= static_cast<std::uint64_t>(frame_count_)) {
    if (!opt_.repeat) {
      at_end_ = true;
      return std::nullopt;
    }
    // Another pass: seek() crashes in Debian's build, so reopen the file.
    pass_offset_ts_us_ = last_ts_us_ + static_cast<std::uint64_t>(1e6 / fps_);
    close_device();
    open_device();
  }
  openni::VideoStream* streams[] = {&impl_->depth};
  int ready = -1;
  const auto rc = openni::OpenNI::waitForAnyStream(streams, 1, &ready, static_cast<int>(timeout.count()));
  if (rc != openni::STATUS_OK) {
    waited_ms_ += timeout.count();
    if (file && frames_this_pass_ == 0) {
      if (waited_ms_ >= 2000) {
        throw std::runtime_error("openni2: no frame came from '" + opt_.uri + "' in " + std::to_string(waited_ms_) +
                                 " ms although it holds " + std::to_string(frame_count_) +
                                 " (OpenNI2's player drops every frame of a stream recorded without a cropping "
                                 "property, as the Dummy device records; mend the file with `skelgraph oni mend`)");
      }
    }
    // A recording without an index ends when no frame comes; one whose
    // player stopped short of its index, after 2 s without a frame (the next
    // call ends the pass, or starts another with repeat).
    if (file && frame_count_ < 0 && frames_this_pass_ > 0) at_end_ = !opt_.repeat;
    if (file && frame_count_ >= 0 && frames_this_pass_ > 0 && waited_ms_ >= 2000 &&
        frames_this_pass_ < static_cast<std::uint64_t>(frame_count_)) {
      never_delivered_ += static_cast<std::uint64_t>(frame_count_) - frames_this_pass_;
      frames_this_pass_ = static_cast<std::uint64_t>(frame_count_);
      waited_ms_ = 0;
    }
    return std::nullopt;
  }
  waited_ms_ = 0;
  if (impl_->depth.readFrame(&impl_->frame) != openni::STATUS_OK || !impl_->frame.isValid()) {
    throw std::runtime_error(oni_error("openni2: reading a depth frame from '" + opt_.uri + "' failed"));
  }
  const auto& f = impl_->frame;
  depth::DepthImage image;
  image.sensor_id = opt_.sensor_id;
  image.intrinsics = intrinsics_;
  image.intrinsics.width = f.getWidth();
  image.intrinsics.height = f.getHeight();
  if (f.getWidth() != intrinsics_.width || f.getHeight() != intrinsics_.height) {
    image.intrinsics = intrinsics_from_device_ ? depth::intrinsics_from_fov(f.getWidth(), f.getHeight(),
                                                                             impl_->depth.getHorizontalFieldOfView(),
                                                                             impl_->depth.getVerticalFieldOfView())
                                               : depth::kinect_intrinsics(f.getWidth(), f.getHeight());
  }
  const int w = f.getWidth(), h = f.getHeight();
  image.mm.resize(static_cast<std::size_t>(w) * h);
  const auto* base = static_cast<const std::uint8_t*>(f.getData());
  const int stride = f.getStrideInBytes() > 0 ? f.getStrideInBytes() : w * 2;
  const bool tenths = f.getVideoMode().getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM;
  for (int v = 0; v < h; ++v) {
    const auto* row = reinterpret_cast<const openni::DepthPixel*>(base + static_cast<std::size_t>(v) * stride);
    auto* out = image.mm.data() + static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) out[u] = tenths ? static_cast<std::uint16_t>(row[u] / 10) : row[u];
  }
  const std::uint64_t ts = f.getTimestamp() + pass_offset_ts_us_;
  last_ts_us_ = ts;
  ++frames_read_;
  ++frames_this_pass_;
  image.frame_number = frames_read_;
  if (!file) {
    image.stamp_ns = opt_.clock->now_ns();
    if (recording()) ++recorded_;
    return image;
  }
  // Recordings: the recorded timing, scaled by the speed, from the first
  // frame (or the first since the speed changed or pacing restarted).
  if (repace_) {
    pace_start_ns_ = opt_.clock->now_ns();
    pace_first_ts_us_ = ts;
    repace_ = false;
  }
  const std::int64_t since_us = static_cast<std::int64_t>(ts - pace_first_ts_us_);
  if (opt_.speed > 0) {
    image.stamp_ns = pace_start_ns_ + static_cast<std::int64_t>(std::llround(since_us * 1000.0 / opt_.speed));
    const auto wait_ns = image.stamp_ns - opt_.clock->now_ns();
    if (wait_ns > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait_ns));
  } else {
    image.stamp_ns = opt_.clock->now_ns();
  }
  return image;
}

void OniSource::set_speed(double speed) {
  if (!(speed >= 0) || !std::isfinite(speed)) throw std::invalid_argument("openni2: speed must be >= 0");
  opt_.speed = speed;
  repace_ = true;
}

void OniSource::start_recording(const std::string& path) {
  if (!impl_) throw std::runtime_error("openni2: device closed");
  if (recording()) stop_recording();
  if (is_file()) throw std::runtime_error("openni2: '" + opt_.uri + "' is a recording; record a device instead");
  const auto dir = std::filesystem::path(path).parent_path();
  if (!dir.empty()) std::filesystem::create_directories(dir);
  auto rec = std::make_unique<openni::Recorder>();
  if (rec->create(path.c_str()) != openni::STATUS_OK) {
    throw std::runtime_error(oni_error("openni2: cannot create recording '" + path + "'"));
  }
  // attach() must come before start(); false: lossless compression.
  if (rec->attach(impl_->depth, false) != openni::STATUS_OK || rec->start() != openni::STATUS_OK) {
    const auto msg = oni_error("openni2: cannot record '" + opt_.uri + "' to '" + path + "'");
    rec->destroy();
    throw std::runtime_error(msg);
  }
  impl_->recorder = std::move(rec);
  impl_->recording_path = path;
  recorded_ = 0;
}

std::uint64_t OniSource::stop_recording() {
  if (!impl_ || !impl_->recorder) return 0;
  impl_->recorder->stop();
  impl_->recorder->destroy();  // writes the index and the end record
  impl_->recorder.reset();
  const std::string path = impl_->recording_path;
  impl_->recording_path.clear();
  if (opt_.mend_recordings) oni_add_cropping(path);
  return recorded_;
}

bool OniSource::recording() const { return impl_ && impl_->recorder != nullptr; }

}  // namespace skelgraph::openni2
