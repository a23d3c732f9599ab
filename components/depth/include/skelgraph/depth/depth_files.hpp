#pragma once
// Depth images kept as files, one per frame, in a folder: 16-bit PGM (P5,
// maxval > 255; big-endian as the format says, or little-endian as some
// tools write), 16-bit PNG, or raw uint16 of a given size and byte order; in
// millimetres (0: no reading). With the camera's intrinsics (an intrinsics
// file as `skelgraph calib intrinsics` writes, or given) and time stamps (a
// file with one time per image, seconds, or a fixed rate). What the
// `depth_files` component plays on skelgraph/depth as the openni2 source
// does. No DDS.
#include <cstdint>
#include <string>
#include <vector>

#include "skelgraph/depth/depth_image.hpp"

namespace skelgraph::depth {

struct DepthFilesOptions {
  std::string format = "auto";      // auto (by extension: .pgm, .png; anything else raw), pgm, png, raw
  int width = 0, height = 0;        // raw: the size (required); pgm/png: checked when given
  std::string byte_order = "auto";  // little or big; auto: big for PGM (its standard), little for raw
  double rate_hz = 30.0;            // the frames' spacing when there is no timestamps file
  std::string timestamps;           // a file: one time per image (seconds, any origin), in the images' order
  std::string intrinsics_file;      // an intrinsics YAML (calib intrinsics); else `intrinsics`
  calib::Intrinsics intrinsics;     // used when no file is given; width/height follow the images
  bool intrinsics_given = false;    // false and no file: Kinect-like for the images' size (kinect_intrinsics)
  std::string sensor_id = "depth1";
  std::string pattern;              // the image files' names (a regex the whole name matches); "": see DepthFolder
};

// One file's pixels (row-major); width/height are set from the file (raw:
// from the options). Throws playback-style errors: std::invalid_argument
// starting "FILE: " and saying what was expected (a 16-bit image, the size,
// the byte count of a raw file, a complete PGM).
std::vector<std::uint16_t> read_depth_file(const std::string& path, const DepthFilesOptions& options, int& width, int& height);

// A folder of depth image files, in name order: those whose names match
// `pattern`, else every regular file but hidden ones, documents (.md, .txt,
// .csv, .yaml, .yml, .json) and licence files (COPYING, LICENSE*, README*).
class DepthFolder {
 public:
  // Throws std::invalid_argument: not a folder, no images, a timestamps file
  // whose count or order does not fit, a bad intrinsics file, a rate <= 0.
  DepthFolder(const std::string& directory, DepthFilesOptions options);
  std::size_t size() const { return files_.size(); }
  const std::string& file(std::size_t i) const { return files_.at(i); }
  std::int64_t offset_ns(std::size_t i) const { return offsets_.at(i); }  // from the first image
  double duration_s() const { return offsets_.empty() ? 0.0 : 1e-9 * static_cast<double>(offsets_.back()); }
  // Image i with its intrinsics and frame number (stamp_ns left 0: the player stamps it).
  DepthImage read(std::size_t i) const;
  const DepthFilesOptions& options() const { return o_; }
  // Raw files' byte counts against the size, without reading them: throws
  // std::invalid_argument naming the first that does not fit (a player
  // refuses such a folder before it plays anything).
  void check_raw_sizes() const;

 private:
  DepthFilesOptions o_;
  std::vector<std::string> files_;
  std::vector<std::int64_t> offsets_;
};

}  // namespace skelgraph::depth
