#include "skelgraph/depth/depth_files.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "skelgraph/calib/calib_file.hpp"

namespace skelgraph::depth {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const std::string& path, const std::string& what) { throw std::invalid_argument(path + ": " + what); }

std::string lower_ext(const std::string& path) {
  auto e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

void swap_bytes(std::vector<std::uint16_t>& v) {
  for (auto& x : v) x = static_cast<std::uint16_t>((x >> 8) | (x << 8));
}

std::vector<std::uint16_t> read_pgm(const std::string& path, bool big_endian, int& width, int& height) {
  std::ifstream in(path, std::ios::binary);
  if (!in) bad(path, "cannot open file");
  std::string magic;
  in >> magic;
  if (magic != "P5") bad(path, "expected a binary PGM ('P5'), got '" + magic.substr(0, 8) + "'");
  const auto next_number = [&](const char* what) {
    in >> std::ws;
    while (in.peek() == '#') {  // comments
      std::string line;
      std::getline(in, line);
      in >> std::ws;
    }
    long long v = -1;
    if (!(in >> v) || v <= 0) bad(path, std::string("expected the PGM header's ") + what + " (a positive number)");
    return v;
  };
  width = static_cast<int>(next_number("width"));
  height = static_cast<int>(next_number("height"));
  const auto maxval = next_number("maxval");
  if (maxval < 256) bad(path, "an 8-bit PGM (maxval " + std::to_string(maxval) + "); expected 16-bit depth (maxval > 255)");
  if (maxval > 65535) bad(path, "PGM maxval " + std::to_string(maxval) + " is above 65535");
  in.get();  // the single whitespace after maxval
  std::vector<std::uint16_t> px(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  in.read(reinterpret_cast<char*>(px.data()), static_cast<std::streamsize>(px.size() * 2));
  if (in.gcount() != static_cast<std::streamsize>(px.size() * 2))
    bad(path, "truncated: " + std::to_string(in.gcount()) + " bytes of pixels, expected " + std::to_string(px.size() * 2) +
                  " (" + std::to_string(width) + " x " + std::to_string(height) + " x 2)");
  if (big_endian) swap_bytes(px);  // the file is big-endian, this machine little
  return px;
}

std::vector<std::uint16_t> read_png(const std::string& path, int& width, int& height) {
  if (!fs::exists(path)) bad(path, "cannot open file");
  const cv::Mat m = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
  if (m.empty()) bad(path, "not a PNG image OpenCV can read");
  if (m.depth() != CV_16U || m.channels() != 1)
    bad(path, std::string(m.elemSize1() == 1 ? "an " : "a ") + std::to_string(m.elemSize1() * 8) + "-bit image with " +
                  std::to_string(m.channels()) +
                  " channel(s); expected 16-bit single-channel depth");
  width = m.cols;
  height = m.rows;
  std::vector<std::uint16_t> px(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int v = 0; v < height; ++v) std::copy_n(m.ptr<std::uint16_t>(v), width, px.data() + static_cast<std::size_t>(v) * width);
  return px;
}

std::vector<std::uint16_t> read_raw(const std::string& path, bool big_endian, int width, int height) {
  if (width <= 0 || height <= 0) bad(path, "a raw depth file needs the image size (width and height)");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) bad(path, "cannot open file");
  const auto bytes = static_cast<std::size_t>(in.tellg());
  const auto want = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 2;
  if (bytes != want)
    bad(path, std::to_string(bytes) + " bytes; a raw " + std::to_string(width) + " x " + std::to_string(height) +
                  " uint16 image has " + std::to_string(want));
  in.seekg(0);
  std::vector<std::uint16_t> px(want / 2);
  in.read(reinterpret_cast<char*>(px.data()), static_cast<std::streamsize>(want));
  if (big_endian) swap_bytes(px);
  return px;
}

}  // namespace

std::vector<std::uint16_t> read_depth_file(const std::string& path, const DepthFilesOptions& o, int& width, int& height) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the readers assume a little-endian machine");
  const auto ext = lower_ext(path);
  const std::string format = o.format != "auto" ? o.format : ext == ".pgm" ? "pgm" : ext == ".png" ? "png" : "raw";
  if (o.byte_order != "auto" && o.byte_order != "little" && o.byte_order != "big")
    throw std::invalid_argument("byte order '" + o.byte_order + "': expected little, big or auto");
  std::vector<std::uint16_t> px;
  if (format == "pgm") {
    px = read_pgm(path, o.byte_order != "little", width, height);
  } else if (format == "png") {
    px = read_png(path, width, height);
  } else if (format == "raw") {
    width = o.width;
    height = o.height;
    px = read_raw(path, o.byte_order == "big", width, height);
  } else {
    throw std::invalid_argument("depth file format '" + o.format + "': expected auto, pgm, png or raw");
  }
  if ((o.width > 0 && width != o.width) || (o.height > 0 && height != o.height))
    bad(path, std::to_string(width) + " x " + std::to_string(height) + " pixels, expected " + std::to_string(o.width) + " x " +
                  std::to_string(o.height));
  return px;
}

DepthFolder::DepthFolder(const std::string& directory, DepthFilesOptions options) : o_(std::move(options)) {
  if (!fs::is_directory(directory)) throw std::invalid_argument(directory + ": not a folder");
  std::optional<std::regex> pattern;
  try {
    if (!o_.pattern.empty()) pattern.emplace(o_.pattern);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("pattern '" + o_.pattern + "': " + e.what());
  }
  for (const auto& e : fs::directory_iterator(directory)) {
    const auto name = e.path().filename().string();
    const auto ext = lower_ext(name);
    if (!e.is_regular_file() || name.empty() || name[0] == '.') continue;
    if (!o_.timestamps.empty() && fs::absolute(e.path()) == fs::absolute(o_.timestamps)) continue;
    if (pattern) {
      if (!std::regex_match(name, *pattern)) continue;
    } else if (ext == ".md" || ext == ".txt" || ext == ".csv" || ext == ".yaml" || ext == ".yml" || ext == ".json" ||
               name == "COPYING" || name.rfind("LICENSE", 0) == 0 || name.rfind("README", 0) == 0) {
      continue;
    }
    files_.push_back(e.path().string());
  }
  std::sort(files_.begin(), files_.end());
  if (files_.empty()) throw std::invalid_argument(directory + ": no depth image files");
  if (!o_.timestamps.empty()) {
    std::ifstream in(o_.timestamps);
    if (!in) throw std::invalid_argument(o_.timestamps + ": cannot open file");
    std::string line;
    std::vector<double> t;
    for (std::size_t n = 1; std::getline(in, line); ++n) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      std::istringstream ls(line);
      double s = 0;
      if (!(ls >> s) || !std::isfinite(s))
        throw std::invalid_argument(o_.timestamps + ":" + std::to_string(n) + ": expected a time in seconds");
      if (!t.empty() && s < t.back())
        throw std::invalid_argument(o_.timestamps + ":" + std::to_string(n) + ": time goes backwards");
      t.push_back(s);
    }
    if (t.size() != files_.size())
      throw std::invalid_argument(o_.timestamps + ": " + std::to_string(t.size()) + " times for " + std::to_string(files_.size()) +
                                  " images in " + directory);
    for (double s : t) offsets_.push_back(static_cast<std::int64_t>(std::llround((s - t.front()) * 1e9)));
  } else {
    if (!(o_.rate_hz > 0)) throw std::invalid_argument("rate must be > 0 Hz without a timestamps file");
    for (std::size_t i = 0; i < files_.size(); ++i)
      offsets_.push_back(static_cast<std::int64_t>(std::llround(static_cast<double>(i) * 1e9 / o_.rate_hz)));
  }
  if (!o_.intrinsics_file.empty()) {
    o_.intrinsics = calib::read_intrinsics_file(o_.intrinsics_file);
    o_.intrinsics_given = true;
  }
}

void DepthFolder::check_raw_sizes() const {
  for (const auto& f : files_) {
    const auto ext = lower_ext(f);
    const bool raw = o_.format == "raw" || (o_.format == "auto" && ext != ".pgm" && ext != ".png");
    if (!raw || o_.width <= 0 || o_.height <= 0) continue;
    const auto bytes = fs::file_size(f);
    const auto want = static_cast<std::uintmax_t>(o_.width) * static_cast<std::uintmax_t>(o_.height) * 2;
    if (bytes != want)
      bad(f, std::to_string(bytes) + " bytes; a raw " + std::to_string(o_.width) + " x " + std::to_string(o_.height) +
                 " uint16 image has " + std::to_string(want));
  }
}

DepthImage DepthFolder::read(std::size_t i) const {
  DepthImage img;
  int w = 0, h = 0;
  img.mm = read_depth_file(files_.at(i), o_, w, h);
  if (o_.intrinsics_given) {
    img.intrinsics = o_.intrinsics;
    if (img.intrinsics.width != w || img.intrinsics.height != h)
      throw std::invalid_argument(files_[i] + ": " + std::to_string(w) + " x " + std::to_string(h) + " pixels; the intrinsics are for " +
                                  std::to_string(img.intrinsics.width) + " x " + std::to_string(img.intrinsics.height));
  } else {
    img.intrinsics = kinect_intrinsics(w, h);
  }
  img.sensor_id = o_.sensor_id;
  img.frame_number = i;
  return img;
}

}  // namespace skelgraph::depth
