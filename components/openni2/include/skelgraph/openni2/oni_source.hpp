#pragma once
// OpenNI2 depth capture without DDS: a device opened by URI (a real sensor
// through the PS1080 driver, an .oni recording through OniFile, or OpenNI2's
// "Dummy" test device), its depth frames as DepthImage, and .oni recording.
// The `openni2` component drives one of these on its own thread.
//
// What Debian's OpenNI2 2.2.0.33 does that callers must know (found by
// experiment, see components/openni2/README.md):
// - the Dummy device is opened by the URI "Dummy" (exactly); 320x240 depth at
//   30 Hz, no field of view (the intrinsics then fall back to Kinect-like ones);
// - recordings are played in step mode (speed -1: a frame per request, none
//   lost) and paced here from their timestamps; PlaybackControl::seek crashes
//   in Debian's build, so a repeat reopens the file;
// - the OniFile player drops every frame of a stream recorded without a
//   cropping property (the Dummy device has none): oni_add_cropping() mends
//   such files, and stop_recording() applies it.
// All calls of one OniSource must come from one thread.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "skelgraph/runtime/clock.hpp"
#include "skelgraph/depth/depth_image.hpp"

namespace skelgraph::openni2 {

struct OniOptions {
  std::string uri = "Dummy";    // "Dummy", a device URI, "any" (the first device), or an .oni file path
  std::string sensor_id = "depth1";
  double speed = 1.0;           // recordings: 1 real time, 2 twice as fast, 0 as fast as frames can be read
  bool repeat = false;          // recordings: start again at the end
  bool mend_recordings = true;  // stop_recording() runs oni_add_cropping() on the file
  // Devices: the depth mode to ask for (0: the device's default); one it does
  // not offer is an error listing the modes it does.
  int width = 0, height = 0, fps = 0;
  // Frames are stamped (and recordings paced) on this clock's wall time.
  std::shared_ptr<const runtime::Clock> clock = runtime::system_clock();
};

class OniSource {
 public:
  // Opens the device and starts its depth stream. Throws std::runtime_error
  // naming the URI and OpenNI's own message (no such device or file, no depth stream).
  explicit OniSource(OniOptions options);
  ~OniSource();
  OniSource(const OniSource&) = delete;
  OniSource& operator=(const OniSource&) = delete;

  bool is_file() const;
  // From the device's field of view; Kinect-like for the image size when it reports none.
  const calib::Intrinsics& intrinsics() const { return intrinsics_; }
  bool intrinsics_from_device() const { return intrinsics_from_device_; }
  double fps() const { return fps_; }
  std::string description() const;  // "Dummy (Table Tennis), depth 320x240 at 30 Hz"
  // Frames in the recording (files with an index), else -1.
  int frame_count() const { return frame_count_; }
  // Frames of an indexed recording OpenNI2's player never delivered: a pass
  // that stops short of the index for 2 s ends there (seen once on a busy
  // machine: 196 of 197), instead of waiting for good.
  std::uint64_t frames_never_delivered() const { return never_delivered_; }

  // The next depth frame, waiting at most `timeout`; nothing on a timeout or
  // at the end of a recording (then at_end() is true). Throws
  // std::runtime_error when a recording delivers no frame at all for 2 s
  // (an unmended recording of a device without cropping). Stamps: the host clock
  // when read (devices), or the start time plus the recording's own timestamps
  // scaled by the speed (files).
  std::optional<depth::DepthImage> next(std::chrono::milliseconds timeout);
  bool at_end() const { return at_end_; }
  // Recordings: a new speed, paced from the next frame on (no burst to catch
  // up, no wait for lost time); restart_pacing() alone does the latter (after
  // a pause). Throws std::invalid_argument for a negative speed.
  void set_speed(double speed);
  void restart_pacing() { repace_ = true; }
  double speed() const { return opt_.speed; }
  std::uint64_t frames_read() const { return frames_read_; }

  // Records the depth stream to an .oni file until stop_recording(), which
  // finalises it and returns the frames written. Throws std::runtime_error.
  void start_recording(const std::string& path);
  std::uint64_t stop_recording();
  bool recording() const;

 private:
  struct Impl;
  void open_device();
  void close_device();
  void choose_mode();
  OniOptions opt_;
  std::unique_ptr<Impl> impl_;
  calib::Intrinsics intrinsics_;
  bool intrinsics_from_device_ = false;
  double fps_ = 30.0;
  int frame_count_ = -1;
  bool at_end_ = false;
  std::uint64_t frames_read_ = 0, frames_this_pass_ = 0, recorded_ = 0;
  std::int64_t pace_start_ns_ = 0;      // files: host time of the pass's first frame
  std::uint64_t pace_first_ts_us_ = 0;  // files: its recorded timestamp
  bool repace_ = true;                  // files: the next frame starts the pacing afresh
  std::uint64_t pass_offset_ts_us_ = 0; // files: timestamps of earlier passes (repeat)
  std::uint64_t last_ts_us_ = 0;
  std::int64_t waited_ms_ = 0;          // files: waited for the next frame
  std::uint64_t never_delivered_ = 0;
};

// Makes an .oni recording playable by the OniFile driver when a depth or
// colour stream in it has no cropping property (recordings of devices that do
// not report one, such as Dummy): an unneeded same-node property record
// ("xnSupportedPixelFormats") is rewritten in place as "cropping disabled", so
// no offsets move; the zero padding Debian's recorder leaves after the end
// record is dropped. Returns the number of streams mended (0: nothing to do);
// throws std::runtime_error for an unreadable or malformed file, or when a
// stream needs mending and has no record that can be rewritten.
int oni_add_cropping(const std::string& path);

}  // namespace skelgraph::openni2
