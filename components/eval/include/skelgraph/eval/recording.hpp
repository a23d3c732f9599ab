#pragma once
// Recordings (MCAP, as the recorder writes them) through the offline
// evaluator: what a recording holds (poses, sync ticks, streams), its
// skeletons streamed in time order (the one ordered queue, held back only as
// far as the file's own disorder requires: a long recording is never held
// whole), scored against its truth, or fused into a copy of it. The library
// behind `skelgraph eval recording|live`, `skelgraph fuse` and the demo.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "skelgraph/eval/offline.hpp"

namespace skelgraph::mcap {
struct Channel;
struct Message;
}  // namespace skelgraph::mcap

namespace skelgraph::eval {

// A recording that cannot be read or scored: names the file and what is missing.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a recording holds for evaluation, from a first pass over it: sensor
// poses (the latest per sensor in the file), sync ticks, counts, and the ids
// of the streams. The skeletons themselves are streamed by stream_recording.
struct RecordingInputs {
  std::string file;
  std::map<std::string, Eigen::Isometry3d> poses;
  std::vector<std::int64_t> ticks;  // log times of the sync TICKs, if the session was synchronised
  std::uint64_t raw = 0, truth = 0, fused = 0;  // fused: recorded live fusion output
  std::vector<std::string> sensor_ids, recorded_ids;  // in order of first appearance
  std::int64_t lateness_ns = 0;  // the most a skeleton's log time falls behind an earlier one's in the file
};

// shared_frame: every sensor's skeletons are already in one frame (data sets
// such as KinectMultiTrack map them so): identity poses, no calibration
// needed. calibration: a calibration file whose poses replace the
// recording's. Throws RecordingError.
RecordingInputs read_recording(const std::string& file, bool shared_frame, const std::string& calibration = "");

// Where a long pass is ("...: 5000 of 90000 skeletons ..."), every 5000
// skeletons of a recording of over 40,000.
using ProgressFn = std::function<void(const std::string&)>;
// Sees every message of the file in file order, after its skeleton went in.
using MessageHook = std::function<void(const mcap::Channel&, const mcap::Message&)>;

// The recording's skeletons into `ev` in time order (ties in file order).
void stream_recording(const RecordingInputs& in, Evaluator& ev, const MessageHook& each = {},
                      const ProgressFn& progress = {});

struct RecordingOptions {
  std::vector<std::string> methods;  // fusion methods by name; empty: all
  double delay_ms = 0, max_age_ms = 100;
  double predict_ms = 0;    // kalman: predicted this far past each fusion time
  double use_delay_ms = 0;  // scored against the truth this long after each output (the time of use)
  bool shared_frame = false;
  std::string calibration;  // a calibration file's poses instead of the recording's
};

// The offline options for these methods and timings (a recording's fusion
// runs on its sync TICKs when it has them, as the live component does, else at 30 Hz).
OfflineOptions offline_options(const std::vector<std::string>& methods, double delay_ms, double max_age_ms);
OfflineOptions offline_options(const RecordingOptions& o, const RecordingInputs& in);

// Single sensors and every method, against the truth in the recording if it
// has one; bone-length steadiness and completeness either way. `summary` is
// the `eval recording --json` object.
struct ScoredRecording {
  RecordingInputs in;
  OfflineResult result;
  nlohmann::json summary;
};
ScoredRecording score_recording(const std::string& file, const RecordingOptions& o, bool trace,
                                const ProgressFn& progress = {});

// `file` with skelgraph/skeleton/fused added (sensor_id "fused", or
// "fused_<method>" for several methods) written to `out`, in one pass: every
// message is copied in file order, each after the fused skeletons up to its
// log time. Returns the `skelgraph fuse --json` summary.
nlohmann::json fuse_recording(const std::string& file, const std::string& out, const RecordingOptions& o,
                              const ProgressFn& progress = {});

}  // namespace skelgraph::eval
