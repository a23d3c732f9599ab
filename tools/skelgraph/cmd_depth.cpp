// skelgraph depth info|play DIR: a folder of depth image files read and
// summarised (no DDS), or played on skelgraph/depth (the depth_files component).

#include <algorithm>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "run_graph.hpp"
#include "skelgraph/depth/depth_files.hpp"

namespace skelgraph::cli {

namespace {

struct DepthOpts {
  std::string dir, format = "auto", byte_order = "auto", intrinsics, timestamps, sensor_id = "depth1", pattern;
  int width = 0, height = 0;
  double rate = 30.0, speed = 1.0;
  bool loop = false, paused = false, json = false;
  RunOptions run;
};

depth::DepthFilesOptions files_options(const DepthOpts& o) {
  depth::DepthFilesOptions f;
  f.format = o.format;
  f.width = o.width;
  f.height = o.height;
  f.byte_order = o.byte_order;
  f.intrinsics_file = o.intrinsics;
  f.timestamps = o.timestamps;
  f.rate_hz = o.rate;
  f.sensor_id = o.sensor_id;
  f.pattern = o.pattern;
  return f;
}

int info(const DepthOpts& o) {
  std::unique_ptr<depth::DepthFolder> folder;
  try {
    folder = std::make_unique<depth::DepthFolder>(o.dir, files_options(o));
  } catch (const std::exception& e) {
    throw UsageError(e.what());
  }
  BadInputs bad;
  nlohmann::json files = nlohmann::json::array();
  std::size_t read = 0;
  for (std::size_t i = 0; i < folder->size(); ++i) {
    depth::DepthImage img;
    const bool ok = bad.guard([&] {
      try {
        img = folder->read(i);
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
    });
    if (!ok) {
      files.push_back({{"file", folder->file(i)}, {"error", bad.messages().back()}});
      continue;
    }
    ++read;
    std::vector<std::uint16_t> valid;
    for (auto v : img.mm)
      if (v > 0) valid.push_back(v);
    std::sort(valid.begin(), valid.end());
    nlohmann::json f{{"file", folder->file(i)},
                     {"time_s", 1e-9 * static_cast<double>(folder->offset_ns(i))},
                     {"width", img.width()},
                     {"height", img.height()},
                     {"valid_pixels", valid.size()},
                     {"valid_share", static_cast<double>(valid.size()) / static_cast<double>(img.mm.size())}};
    if (!valid.empty()) {
      f["min_mm"] = valid.front();
      f["median_mm"] = valid[valid.size() / 2];
      f["max_mm"] = valid.back();
    }
    if (!o.json)
      std::printf("%s: %d x %d, %.1f %% with a reading%s\n", folder->file(i).c_str(), img.width(), img.height(),
                  100.0 * f["valid_share"].get<double>(),
                  valid.empty() ? "" : (", " + std::to_string(valid.front()) + "-" + std::to_string(valid.back()) + " mm, median " +
                                        std::to_string(valid[valid.size() / 2]) + " mm").c_str());
    files.push_back(std::move(f));
  }
  const auto& k = folder->options().intrinsics;
  nlohmann::json out{{"directory", o.dir},
                     {"images", folder->size()},
                     {"read", read},
                     {"duration_s", folder->duration_s()},
                     {"intrinsics", folder->options().intrinsics_given
                                        ? nlohmann::json{{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}}
                                        : nlohmann::json("Kinect-like for the images' size (none given)")},
                     {"files", files}};
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
  else std::printf("%zu of %zu images read, %.2f s\n", read, folder->size(), folder->duration_s());
  return bad.exit_code(0, folder->size());
}

void add_files_options(CLI::App* c, DepthOpts& o) {
  c->add_option("directory", o.dir, "the folder of depth images (every file but .txt/.yaml/.json, in name order)")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("--pattern", o.pattern, "the image files' names: a regex the whole name matches (default: every file but "
                                        "documents and licences)");
  c->add_option("--format", o.format, "auto (by extension; anything but .pgm/.png is raw), pgm, png, raw")
      ->check(CLI::IsMember({"auto", "pgm", "png", "raw"}));
  c->add_option("--width", o.width, "raw: image width (others: checked)")->check(CLI::Range(0, 16384));
  c->add_option("--height", o.height, "raw: image height (others: checked)")->check(CLI::Range(0, 16384));
  c->add_option("--byte-order", o.byte_order, "auto (PGM big-endian, raw little-endian), little or big")
      ->check(CLI::IsMember({"auto", "little", "big"}));
  c->add_option("--intrinsics", o.intrinsics, "intrinsics YAML (skelgraph calib intrinsics); default Kinect-like")
      ->check(CLI::ExistingFile);
  c->add_option("--timestamps", o.timestamps, "a file with one time per image (seconds); else --rate")->check(CLI::ExistingFile);
  c->add_option("--rate", o.rate, "frames per second without --timestamps (default 30)")->check(kPositive);
  c->add_option("--sensor-id", o.sensor_id, "the sensor's name on skelgraph/depth (default depth1)");
}

}  // namespace

void add_depth_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto* d = app.add_subcommand("depth", "Depth image files: read and summarise a folder, or play it on skelgraph/depth");
  d->require_subcommand(1);
  auto o = std::make_shared<DepthOpts>();
  auto* in = d->add_subcommand("info", "Read every image of a folder and summarise it (size, pixels with a reading, depth range)");
  add_files_options(in, *o);
  in->add_flag("--json", o->json, "machine-readable output");
  in->callback([o, &run] { run = [o] { return info(*o); }; });

  auto* pl = d->add_subcommand("play", "Play a folder of depth images on skelgraph/depth (the depth_files component)");
  add_files_options(pl, *o);
  pl->add_option("--speed", o->speed, "1 as the times say, 2 twice as fast, 0 as fast as possible")->check(kNonNegative);
  pl->add_flag("--loop", o->loop, "start again at the end");
  pl->add_flag("--paused", o->paused, "start paused (then skelgraph player step|resume)");
  add_run_options(*pl, o->run);
  add_dds_options(*pl, g);
  pl->callback([o, &g, &run] {
    run = [o, &g] {
      const std::vector<runtime::RawParam> raw = {
          {"directory", o->dir, "depth play"},       {"format", o->format, "depth play"},
          {"width", std::to_string(o->width), "depth play"}, {"height", std::to_string(o->height), "depth play"},
          {"byte_order", o->byte_order, "depth play"}, {"intrinsics", o->intrinsics, "depth play"},
          {"timestamps", o->timestamps, "depth play"}, {"rate", std::to_string(o->rate), "depth play"},
          {"speed", std::to_string(o->speed), "depth play"}, {"loop", o->loop ? "true" : "false", "depth play"},
          {"paused", o->paused ? "true" : "false", "depth play"}, {"sensor_id", o->sensor_id, "depth play"},
          {"pattern", o->pattern, "depth play"}};
      return run_components(g, {{"depth_files", "depth_files", raw}}, o->run);
    };
  });
}

}  // namespace skelgraph::cli
