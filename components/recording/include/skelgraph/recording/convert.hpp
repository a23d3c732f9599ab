#pragma once
// Recordings to and from other files (`skelgraph bag import`, `import-bvh`,
// `export`): data-set skeleton files into a recording on skeleton/raw; motion
// capture (BVH) as the truth on skeleton/truth, alone or added to a copy of a
// recording; a recording's skeletons out to CSV files, one per topic and
// sensor. No DDS.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/playback/readers.hpp"

namespace skelgraph::recording {

// An input the conversion cannot take (a negative time stamp); the message names the file.
class ConvertError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Every frame of `files` (read as `format`) on skelgraph/skeleton/raw of a
// new recording `out`, each file's metadata as an "import" record; `on_file`
// after each file with its frame count. Returns the frames written. Throws
// playback::DataError (a bad file, with file and line), mcap::McapError,
// ConvertError.
std::uint64_t import_skeletons(playback::Format format, const std::vector<std::string>& files,
                               const playback::ReadOptions& options, const std::string& out, mcap::Compression compression,
                               const std::function<void(const std::string& file, std::size_t frames)>& on_file = {});

struct MocapImport {
  std::string file, out;   // the BVH file; the recording written
  std::string add_to;      // a recording copied into `out` first (its own truth left out), or ""
  std::string transform;   // the mocap frame into the target frame (calib::read_transform_file), or ""
  std::string mocap_id = "mocap";  // the motion-capture system's entry in a calibration file as `transform`
  std::string mapping;     // YAML joints: {head: NAME, ...}, or ""
  std::string time_points; // CSV mocap_frame,time_s, or ""
  std::string units = "cm";  // cm, mm, m, in
  std::string frame_id = "world";
  std::optional<double> time_offset;  // frame 0's time, s (default: add_to's first message, else 0)
};

struct MocapImportSummary {
  std::size_t truth_frames = 0;
  double span_s = 0, time_offset_s = 0;
  std::uint64_t copied = 0;  // messages of add_to
};

// Throws playback::DataError, mcap::McapError, calib::CalibFileError (the
// transform), ConvertError (a negative time stamp: give a time offset).
MocapImportSummary import_mocap(const MocapImport& o);

enum class SkeletonCsv {
  Generic,  // skelgraph's lossless CSV (the generic reader reads it back)
  Columns,  // numeric columns per sensor, a line per frame, as the thesis's per-Kinect logs: time, person, x, y, z, confidence per joint
};

// Every skeleton of `file` into DIR/<topic tail>_<sensor>.csv. Returns each file written with its frames.
std::vector<std::pair<std::string, std::size_t>> export_skeletons(const std::string& file, SkeletonCsv format,
                                                                  const std::string& dir);

}  // namespace skelgraph::recording
