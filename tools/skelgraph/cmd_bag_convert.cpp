// skelgraph bag import, import-bvh, export: recordings to and from other files
// (recording/convert.hpp), and a recording with the cell as a 3-D scene
// (scene/scene_export.hpp).

#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cmd_bag.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/scene/scene_export.hpp"

namespace skelgraph::cli::bag_cmd {

namespace {

int import(playback::Format format, const std::vector<std::string>& files, const playback::ReadOptions& opt,
           const std::string& out, mcap::Compression compression, bool json) {
  const auto frames = file_input([&] {
    return recording::import_skeletons(format, files, opt, out, compression, [&](const std::string& f, std::size_t n) {
      if (!json) std::fprintf(stderr, "%s: %zu frames\n", f.c_str(), n);
    });
  });
  if (json) std::printf("%s\n", nlohmann::json{{"out", out}, {"frames", frames}, {"files", files}}.dump(2).c_str());
  else std::printf("%s: %llu skeletons from %zu file(s)\n", out.c_str(), static_cast<unsigned long long>(frames), files.size());
  return 0;
}

struct MocapOptions : recording::MocapImport {
  bool json = false;
};

// Motion capture (BVH) as ground truth on skelgraph/skeleton/truth, alone or
// added to a copy of a recording (so `eval recording` scores it against the mocap).
int import_bvh(const MocapOptions& o) {
  const auto r = file_input([&] { return recording::import_mocap(o); });
  if (o.json)
    std::printf("%s\n", nlohmann::json{{"out", o.out}, {"truth_frames", r.truth_frames}, {"span_s", r.span_s}, {"copied", r.copied},
                                       {"time_offset_s", r.time_offset_s}}
                            .dump(2)
                            .c_str());
  else
    std::printf("%s: %zu mocap frames (%.1f s) on %s%s\n", o.out.c_str(), r.truth_frames, r.span_s,
                runtime::topics::kSkeletonTruth.name,
                o.add_to.empty() ? "" : (", with the " + std::to_string(r.copied) + " messages of " + o.add_to).c_str());
  return 0;
}

// The recording with the cell as a 3-D scene for Foxglove/Lichtblick added (scene_export.hpp).
int export_scene(const std::string& file, const std::string& out, const std::string& compression, bool json) {
  mcap::WriterOptions w;
  w.compression = *mcap::compression_from_name(compression);
  Progress progress(!json);
  const auto r = file_input([&] {
    return scene::export_scene(file, out, {}, w, [&](std::uint64_t done, std::uint64_t total) {
      progress("copied " + std::to_string(done) + "/" + std::to_string(total) + " messages", done >= total);
    });
  });
  progress.done();
  if (json) {
    std::printf("%s\n", nlohmann::json{{"out", out},
                                       {"copied", r.copied},
                                       {"skeletons", r.skeletons},
                                       {"poses", r.poses},
                                       {"pointing", r.pointing},
                                       {"robot_states", r.robot_states},
                                       {"safety", r.safety},
                                       {"scene_updates", r.updates},
                                       {"entities", r.entities},
                                       {"transforms", r.transforms},
                                       {"undecodable", r.undecodable},
                                       {"unplaced_frames", r.unplaced}}
                            .dump(2)
                            .c_str());
  } else {
    std::printf("%s: the %llu messages of %s, and the scene: %llu updates (%llu entities from %llu skeletons, %llu pointing "
                "events, %llu robot states) on %s, %llu transforms on %s\n",
                out.c_str(), static_cast<unsigned long long>(r.copied), file.c_str(), static_cast<unsigned long long>(r.updates),
                static_cast<unsigned long long>(r.entities), static_cast<unsigned long long>(r.skeletons),
                static_cast<unsigned long long>(r.pointing), static_cast<unsigned long long>(r.robot_states), scene::kSceneTopic,
                static_cast<unsigned long long>(r.transforms), scene::kTransformTopic);
  }
  for (const auto& f : r.unplaced)
    std::fprintf(stderr, "note: frame '%s' has no pose in the recording: drawn at the world's origin\n", f.c_str());
  if (r.undecodable > 0) std::fprintf(stderr, "warning: %llu messages did not decode and are not in the scene\n",
                                      static_cast<unsigned long long>(r.undecodable));
  return 0;
}

// Skeletons to CSV: generic (lossless, reads back) or plain numeric columns.
int export_bag(const std::string& file, const std::string& format, const std::string& dir, bool json) {
  const auto files = file_input([&] {
    return recording::export_skeletons(file, format == "generic" ? recording::SkeletonCsv::Generic : recording::SkeletonCsv::Columns,
                                       dir);
  });
  nlohmann::json written = nlohmann::json::object();
  for (const auto& [path, frames] : files) written[path] = frames;
  if (json) std::printf("%s\n", nlohmann::json{{"files", written}}.dump(2).c_str());
  else for (const auto& [p, n] : written.items()) std::printf("%s: %s frames\n", p.c_str(), n.dump().c_str());
  return 0;
}

}  // namespace

void add_convert_commands(CLI::App& bag_app, Action& run) {
  auto* bag = &bag_app;
  struct Opts {
    std::string file, out, format = "csv", compression = "zstd", on_error = "stop", sensor_id;
    std::vector<std::string> files;
    bool json = false, scene = false;
  };
  auto o = std::make_shared<Opts>();
  auto* im = bag->add_subcommand("import", "Data-set files (the playback formats) into an MCAP recording on skelgraph/skeleton/raw");
  im->add_option("format", o->format, "file format")->required()->check(CLI::IsMember(playback::format_names()));
  im->add_option("files", o->files, "files to import")->required()->check(CLI::ExistingFile);
  im->add_option("--out", o->out, "MCAP file to write")->required();
  im->add_option("--compression", o->compression, "chunk compression")->check(CLI::IsMember({"none", "lz4", "zstd"}));
  im->add_option("--on-error", o->on_error, "a bad line: stop (default) or skip it")->check(CLI::IsMember({"stop", "skip"}));
  im->add_option("--sensor-id", o->sensor_id, "sensor id to record under (multitrack: a prefix)");
  im->add_flag("--json", o->json, "machine-readable summary");
  im->callback([o, &run] {
    run = [o] {
      playback::ReadOptions opt;
      opt.on_error = o->on_error == "skip" ? playback::ReadOptions::OnError::Skip : playback::ReadOptions::OnError::Stop;
      opt.sensor_id = o->sensor_id;
      return import(*playback::format_from_name(o->format), o->files, opt, o->out,
                    *mcap::compression_from_name(o->compression), o->json);
    };
  });

  auto mo = std::make_shared<MocapOptions>();
  auto* ib = bag->add_subcommand("import-bvh", "Motion capture (BVH) as ground truth on skelgraph/skeleton/truth, alone or added "
                                              "to a copy of a recording, so `eval recording` scores the recording against it");
  ib->add_option("file", mo->file, "BVH file")->required()->check(CLI::ExistingFile);
  ib->add_option("--out", mo->out, "MCAP file to write")->required();
  ib->add_option("--add-to", mo->add_to, "a recording copied into --out first (its own truth left out)")->check(CLI::ExistingFile);
  ib->add_option("--units", mo->units, "the BVH's length unit: cm (default), mm, m, in")->check(CLI::IsMember({"cm", "mm", "m", "in"}));
  ib->add_option("--transform", mo->transform,
                 "the mocap frame into the target frame: YAML with rotation: [9, row-major] and translation: [x, y, z] metres, "
                 "or a calibration file with the motion-capture system as a sensor (--mocap-id)")
      ->check(CLI::ExistingFile);
  ib->add_option("--frame-id", mo->frame_id, "the frame the positions end up in (default world; a sensor's id for its frame)");
  ib->add_option("--time-offset", mo->time_offset,
                 "frame 0's time, seconds on the recording's clock (default: the --add-to recording's first message, else 0)");
  ib->add_option("--mocap-id", mo->mocap_id, "with a calibration file as --transform: the motion-capture system's entry (default mocap)");
  ib->add_option("--time-points", mo->time_points,
                 "CSV mocap_frame,time_s: matched moments (recording clock, s); frame times follow the line through them "
                 "(instead of --time-offset and the file's frame time)")
      ->check(CLI::ExistingFile)
      ->excludes("--time-offset");
  ib->add_option("--mapping", mo->mapping, "YAML joints: {head: NAME, ...} for names the default mapping does not know")
      ->check(CLI::ExistingFile);
  ib->add_flag("--json", mo->json, "machine-readable summary");
  ib->callback([mo, &run] { run = [mo] { return import_bvh(*mo); }; });

  auto* ex = bag->add_subcommand("export", "Skeletons of a recording to CSV files, one per topic and sensor; or with --scene the "
                                          "recording with the cell as a 3-D scene for Foxglove/Lichtblick added");
  ex->add_option("file", o->file, "MCAP file")->required()->check(CLI::ExistingFile);
  auto* fmt = ex->add_option("--format", o->format, "csv: numeric columns (x, y, z, confidence per joint); generic: skelgraph's lossless CSV")
      ->check(CLI::IsMember({"csv", "generic"}));
  auto* scene_flag = ex->add_flag("--scene", o->scene,
               "--out is an MCAP file: every message of FILE plus foxglove::SceneUpdate on skelgraph/scene/update (skeletons, "
               "sensors, pointing, the robot) and foxglove::FrameTransform on skelgraph/scene/transforms");
  scene_flag->excludes(fmt);
  ex->add_option("--compression", o->compression, "--scene: chunk compression (default zstd)")
      ->check(CLI::IsMember({"none", "lz4", "zstd"}))
      ->needs(scene_flag);
  ex->add_option("--out", o->out, "output directory (--scene: the MCAP file)")->required();
  ex->add_flag("--json", o->json, "machine-readable summary");
  ex->callback([o, &run] {
    run = [o] { return o->scene ? export_scene(o->file, o->out, o->compression, o->json) : export_bag(o->file, o->format, o->out, o->json); };
  });

}

}  // namespace skelgraph::cli::bag_cmd
