// Depth image files: 16-bit PGM in either byte order, 16-bit PNG, raw uint16;
// bad files named with what was expected; a folder's order, times and
// intrinsics; the real Kinect images in ../shared/data/skeltrack-depth.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/depth/depth_files.hpp"

using namespace skelgraph::depth;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const auto d = fs::path(::testing::TempDir()) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A w x h image whose pixel (u, v) is 1000 + 10 v + u.
std::vector<std::uint16_t> ramp(int w, int h) {
  std::vector<std::uint16_t> px;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) px.push_back(static_cast<std::uint16_t>(1000 + 10 * v + u));
  return px;
}

void write_pgm(const fs::path& p, int w, int h, const std::vector<std::uint16_t>& px, bool big, int maxval = 65535) {
  std::ofstream f(p, std::ios::binary);
  f << "P5\n# a comment\n" << w << " " << h << "\n" << maxval << "\n";
  for (auto v : px) {
    const char b[2] = {static_cast<char>(big ? v >> 8 : v & 0xff), static_cast<char>(big ? v & 0xff : v >> 8)};
    f.write(b, 2);
  }
}

void write_raw(const fs::path& p, const std::vector<std::uint16_t>& px) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(px.data()), static_cast<std::streamsize>(px.size() * 2));
}

DepthFilesOptions sized(int w, int h) {
  DepthFilesOptions o;
  o.width = w;
  o.height = h;
  return o;
}

std::string error_of(const fs::path& p, const DepthFilesOptions& o) {
  int w = 0, h = 0;
  try {
    read_depth_file(p.string(), o, w, h);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(DepthFiles, EveryFormatReadsTheSamePixels) {
  const auto d = fresh_dir("depth_formats");
  const auto px = ramp(4, 3);
  write_pgm(d / "big.pgm", 4, 3, px, true);
  write_pgm(d / "little.pgm", 4, 3, px, false);
  write_raw(d / "frame.raw", px);
  cv::Mat m(3, 4, CV_16UC1);
  for (int v = 0; v < 3; ++v)
    for (int u = 0; u < 4; ++u) m.at<std::uint16_t>(v, u) = px[static_cast<std::size_t>(v * 4 + u)];
  ASSERT_TRUE(cv::imwrite((d / "frame.png").string(), m));
  DepthFilesOptions o;
  int w = 0, h = 0;
  EXPECT_EQ(read_depth_file((d / "big.pgm").string(), o, w, h), px);
  EXPECT_EQ(w, 4);
  EXPECT_EQ(h, 3);
  o.byte_order = "little";
  EXPECT_EQ(read_depth_file((d / "little.pgm").string(), o, w, h), px);
  EXPECT_EQ(read_depth_file((d / "frame.raw").string(), sized(4, 3), w, h), px);
  EXPECT_EQ(read_depth_file((d / "frame.png").string(), DepthFilesOptions{}, w, h), px);
}

TEST(DepthFiles, BadFilesSayWhatWasExpected) {
  const auto d = fresh_dir("depth_bad");
  write_pgm(d / "eight.pgm", 2, 2, {1, 2, 3, 4}, true, 255);
  EXPECT_NE(error_of(d / "eight.pgm", {}).find("eight.pgm: an 8-bit PGM (maxval 255)"), std::string::npos);
  {
    std::ofstream f(d / "short.pgm", std::ios::binary);
    f << "P5\n4 3\n65535\n" << std::string(10, '\0');
  }
  EXPECT_NE(error_of(d / "short.pgm", {}).find("short.pgm: truncated: 10 bytes of pixels, expected 24"), std::string::npos);
  std::ofstream(d / "text.pgm") << "P2\n1 1\n65535\n7\n";
  EXPECT_NE(error_of(d / "text.pgm", {}).find("expected a binary PGM ('P5'), got 'P2'"), std::string::npos);
  cv::Mat eight(2, 2, CV_8UC1, cv::Scalar(7));
  ASSERT_TRUE(cv::imwrite((d / "eight.png").string(), eight));
  EXPECT_NE(error_of(d / "eight.png", {}).find("eight.png: an 8-bit image with 1 channel(s); expected 16-bit"), std::string::npos);
  write_raw(d / "odd.raw", ramp(3, 3));
  EXPECT_NE(error_of(d / "odd.raw", sized(4, 3)).find("odd.raw: 18 bytes; a raw 4 x 3 uint16 image has 24"),
            std::string::npos);
  EXPECT_NE(error_of(d / "odd.raw", {}).find("needs the image size"), std::string::npos);
  write_pgm(d / "small.pgm", 4, 3, ramp(4, 3), true);
  EXPECT_NE(error_of(d / "small.pgm", sized(640, 480)).find("4 x 3 pixels, expected 640 x 480"),
            std::string::npos);
  EXPECT_NE(error_of(d / "none.png", {}).find("none.png: cannot open file"), std::string::npos);
}

TEST(DepthFiles, AFolderInNameOrderWithTimesAndIntrinsics) {
  const auto d = fresh_dir("depth_folder");
  for (const char* n : {"b.pgm", "a.pgm", "c.pgm"}) write_pgm(d / n, 4, 3, ramp(4, 3), true);
  std::ofstream(d / "README.md") << "not an image";
  DepthFilesOptions o;
  o.rate_hz = 10;
  DepthFolder f(d.string(), o);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(fs::path(f.file(0)).filename(), "a.pgm");
  EXPECT_EQ(f.offset_ns(2), 200'000'000);
  const auto img = f.read(1);
  EXPECT_EQ(img.frame_number, 1u);
  EXPECT_EQ(img.width(), 4);
  EXPECT_EQ(img.intrinsics.width, 4);  // Kinect-like for the images' size
  // Times from a file (any origin, seconds); a count that does not fit is refused.
  std::ofstream(d / "times.txt") << "100.0\n100.5\n\n101.25\n";
  o.timestamps = (d / "times.txt").string();
  DepthFolder timed(d.string(), o);
  EXPECT_EQ(timed.offset_ns(1), 500'000'000);
  EXPECT_EQ(timed.offset_ns(2), 1'250'000'000);
  std::ofstream(d / "times.txt") << "1\n2\n";
  EXPECT_THROW(DepthFolder(d.string(), o), std::invalid_argument);
  std::ofstream(d / "times.txt") << "1\n3\n2\n";
  try {
    DepthFolder(d.string(), o);
    ADD_FAILURE() << "times going backwards were taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("times.txt:3: time goes backwards"), std::string::npos) << e.what();
  }
  o.timestamps.clear();
  o.pattern = "[ab]\\.pgm";
  // A raw file of the wrong size is found without reading it (a player refuses the folder before it plays).
  {
    const auto r = fresh_dir("depth_raw_sizes");
    write_raw(r / "a.raw", ramp(4, 3));
    write_raw(r / "b.raw", ramp(4, 2));
    DepthFilesOptions ro;
    ro.width = 4;
    ro.height = 3;
    const DepthFolder folder(r.string(), ro);
    EXPECT_NO_THROW(folder.read(0));
    try {
      folder.check_raw_sizes();
      ADD_FAILURE() << "a short raw file was taken";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("b.raw: 16 bytes; a raw 4 x 3 uint16 image has 24"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(DepthFolder(d.string(), o).size(), 2u);
  // An intrinsics file for another size is refused when the image is read.
  skelgraph::calib::Intrinsics k;  // 640 x 480
  skelgraph::calib::write_intrinsics_file((d / "k.yaml").string(), k, 0.2, 10, "test");
  o.pattern.clear();
  o.intrinsics_file = (d / "k.yaml").string();
  DepthFolder with_k(d.string(), o);
  EXPECT_EQ(with_k.size(), 3u);  // k.yaml is not an image
  EXPECT_THROW(with_k.read(0), std::invalid_argument);
}

// The 12 real Kinect v1 images (raw 640 x 480 little-endian, background removed).
TEST(SharedData, SkeltrackDepthImagesRead) {
  const char* env = std::getenv("SKELGRAPH_DATA_DIR");
  const char* src = std::getenv("SKELGRAPH_SOURCE_DIR");
  const fs::path dir = (env ? fs::path(env) : fs::path(src ? src : ".") / ".." / "shared" / "data") / "skeltrack-depth";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)";
  DepthFilesOptions o;
  o.width = 640;
  o.height = 480;
  DepthFolder f(dir.string(), o);
  ASSERT_EQ(f.size(), 12u);
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto img = f.read(i);
    std::uint16_t lo = 65535, hi = 0;
    std::size_t valid = 0;
    for (auto v : img.mm) {
      if (v == 0) continue;
      ++valid;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    EXPECT_GT(valid, 30000u) << f.file(i);
    EXPECT_GE(lo, 723) << f.file(i);  // the data set's README: 723-1992 mm
    EXPECT_LE(hi, 1992) << f.file(i);
  }
}
