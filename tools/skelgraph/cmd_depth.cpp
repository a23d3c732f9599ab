// skelgraph depth info|play DIR: a folder of depth image files read and
// summarised (no DDS), or played on skelgraph/depth (the depth_files component).

#include <algorithm>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "run_graph.hpp"
#include "skelgraph/depth/depth_files.hpp"
#include "skelgraph/depth_tracker/image_check.hpp"
#include "skelgraph/depth_tracker/tracker.hpp"

namespace skelgraph::cli {

namespace {

struct DepthOpts {
  std::string dir, format = "auto", byte_order = "auto", intrinsics, timestamps, sensor_id = "depth1", pattern;
  int width = 0, height = 0;
  double rate = 30.0, speed = 1.0;
  bool loop = false, paused = false, json = false;
  double sensor_height = 1.2, on_person_m = 0.05;
  bool each_alone = false;
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

// The tracker over a folder, offline: per image the people found and whether
// each reported joint of the nearest lies on the person (its pixel has a
// reading and the joint is no more than `on_person_m` in front of it); per
// bone of the nearest person, its length's spread over the images.
int track(const DepthOpts& o) {
  std::unique_ptr<depth::DepthFolder> folder;
  try {
    folder = std::make_unique<depth::DepthFolder>(o.dir, files_options(o));
  } catch (const std::exception& e) {
    throw UsageError(e.what());
  }
  depth_tracker::TrackerOptions topt;
  depth_tracker::DepthTracker tracker(topt);
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();  // a level sensor, sensor_height above the floor
  level.translation() = Eigen::Vector3d(0.0, o.sensor_height, 0.0);
  tracker.set_pose(level);
  BadInputs bad;
  nlohmann::json images = nlohmann::json::array();
  depth_tracker::BoneSpreads bones;
  std::size_t with_one = 0, with_any = 0, joints_reported = 0, joints_on = 0;
  for (std::size_t i = 0; i < folder->size(); ++i) {
    depth::DepthImage img;
    if (!bad.guard([&] {
          try {
            img = folder->read(i);
          } catch (const std::invalid_argument& e) {
            throw UsageError(e.what());
          }
        }))
      continue;
    img.stamp_ns = folder->offset_ns(i);
    if (o.each_alone) {  // snapshots, not a recording: nobody carried over from the image before
      tracker = depth_tracker::DepthTracker(topt);
      tracker.set_pose(level);
    }
    const auto people = tracker.track(img);
    if (people.size() == 1) ++with_one;
    if (!people.empty()) ++with_any;
    nlohmann::json ps = nlohmann::json::array();
    std::size_t nearest = 0;
    for (const auto& p : depth_tracker::check_people(img, people, o.on_person_m)) {
      nlohmann::json joints = nlohmann::json::object();
      for (const auto& j : p.joints) {
        joints[skeleton::joint_name(j.joint)] = {
            {"pixel", {j.pixel.x(), j.pixel.y()}}, {"confidence", j.confidence}, {"on_person", j.on_person}};
      }
      if (p.nearest) {
        nearest = ps.size();
        joints_reported += p.joints.size();
        joints_on += p.on_person;
        bones.add(people[nearest]);
      }
      ps.push_back({{"person", p.person_id}, {"nearest", p.nearest}, {"joints_reported", p.joints.size()},
                    {"joints_on_person", p.on_person}, {"joints", joints}});
    }
    if (!o.json)
      std::printf("%s: %zu people%s\n", folder->file(i).c_str(), people.size(),
                  people.empty() ? "" : (", the nearest's joints on the person " + std::to_string(ps[nearest]["joints_on_person"].get<std::size_t>()) +
                                         " of " + std::to_string(ps[nearest]["joints_reported"].get<std::size_t>())).c_str());
    images.push_back({{"file", folder->file(i)}, {"people", people.size()}, {"skeletons", ps}});
  }
  nlohmann::json spread = nlohmann::json::object();
  for (const auto& [name, b] : bones.summary()) {
    spread[name] = {{"images", b.images}, {"mean_m", b.mean_m}, {"sd_m", b.sd_m}};
    if (!o.json) std::printf("  %-28s %2zu images, mean %.3f m, sd %.3f m\n", name.c_str(), b.images, b.mean_m, b.sd_m);
  }
  nlohmann::json out{{"directory", o.dir},      {"images", folder->size()},        {"with_one_person", with_one},
                     {"with_a_person", with_any},
                     {"nearest_joints_reported", joints_reported}, {"nearest_joints_on_person", joints_on}, {"bones", spread},
                     {"files", images}};
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
  else
    std::printf("%zu of %zu images with a person (%zu with only one); the nearest person's joints on the person: %zu of %zu\n",
                with_any, folder->size(), with_one, joints_on, joints_reported);
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

  auto* tr = d->add_subcommand("track", "Run the depth tracker over a folder offline: the people in each image, whether "
                                         "each joint lies on the person, and each bone's spread over the images");
  add_files_options(tr, *o);
  tr->add_option("--sensor-height", o->sensor_height, "the sensor's height above the floor, level (default 1.2 m)")
      ->check(kPositive);
  tr->add_option("--on-person", o->on_person_m, "a joint this far in front of the surface at its pixel is off the person (m)")
      ->check(kPositive);
  tr->add_flag("--each-alone", o->each_alone, "the images are snapshots, not a recording: track each from scratch");
  tr->add_flag("--json", o->json, "per image and per bone, as JSON");
  tr->callback([o, &run] { run = [o] { return track(*o); }; });
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
