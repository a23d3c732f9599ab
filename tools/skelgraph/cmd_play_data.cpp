// skelgraph play-data FORMAT FILE...: replay recorded data sets (the playback
// component without a launch file), or with --info just read and summarise them.

#include <cstdio>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "run_graph.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/runtime/registry.hpp"

namespace skelgraph::cli {

namespace {

// Reads the files (no DDS) and prints what a replay would publish; a bad file
// is reported (and listed with its error) and the others still read.
int info(playback::Format format, const std::vector<std::string>& files, const playback::ReadOptions& opt) {
  nlohmann::json out = nlohmann::json::array();
  BadInputs bad;
  for (const auto& f : files) {
    playback::Recording rec;
    if (!bad.guard([&] { rec = playback::read_recording(format, f, opt); })) {
      out.push_back({{"file", f}, {"error", bad.messages().back()}});
      continue;
    }
    std::map<std::string, std::set<std::uint32_t>> people;
    std::size_t lost = 0;
    for (const auto& s : rec.frames) {
      people[s.sensor_id].insert(s.person_id);
      for (const auto& j : s.joints) lost += j.confidence == skeleton::kLost ? 1 : 0;
    }
    nlohmann::json sensors = nlohmann::json::object();
    for (const auto& [sensor, ids] : people) sensors[sensor] = ids;
    const double span =
        rec.frames.size() > 1 ? static_cast<double>(rec.frames.back().stamp_ns - rec.frames.front().stamp_ns) * 1e-9 : 0.0;
    out.push_back({{"file", f},
                   {"format", rec.format},
                   {"frames", rec.frames.size()},
                   {"span_s", span},
                   {"sensors_people", sensors},
                   {"lost_joints", lost},
                   {"metadata", rec.metadata},
                   {"labelled_frames", rec.frame_labels.size()},
                   {"annotations", rec.annotations.size()},
                   {"empty_frames", rec.report.empty_frames},
                   {"lines", rec.report.lines},
                   {"skipped_lines", rec.report.skipped},
                   {"repeated_stamps", rec.report.repeated_stamps},
                   {"problems", rec.report.problems}});
  }
  std::printf("%s\n", out.dump(2).c_str());
  return bad.exit_code(0, files.size());
}

}  // namespace

void add_play_data_command(CLI::App& app, GlobalOptions& g, Action& run) {
  struct Opts {
    std::string format;
    std::vector<std::string> files;
    double rate = 1.0;
    bool loop = false;
    std::string on_error = "stop";
    std::string sensor_id;
    bool info = false;
    RunOptions run;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("play-data", "Replay recorded skeleton data sets on skelgraph/skeleton/raw");
  cmd->add_option("format", o->format, "file format")->required()->check(CLI::IsMember(playback::format_names()));
  cmd->add_option("files", o->files, "files to play, merged in time order")->required()->check(CLI::ExistingFile);
  cmd->add_option("--rate", o->rate, "1 = as recorded, 2 = twice as fast, 0 = as fast as possible")->check(kNonNegative);
  cmd->add_flag("--loop", o->loop, "start again at the end");
  cmd->add_option("--on-error", o->on_error, "a bad line: stop (default) or skip it")->check(CLI::IsMember({"stop", "skip"}));
  cmd->add_option("--sensor-id", o->sensor_id, "sensor id to publish under (multitrack: a prefix)");
  cmd->add_flag("--info", o->info, "read the files and print a JSON summary; publish nothing");
  add_run_options(*cmd, o->run);
  add_dds_options(*cmd, g);
  cmd->callback([o, &g, &run] {
    run = [o, &g] {
      if (o->info) {
        playback::ReadOptions opt;
        opt.on_error = o->on_error == "skip" ? playback::ReadOptions::OnError::Skip : playback::ReadOptions::OnError::Stop;
        opt.sensor_id = o->sensor_id;
        return info(*playback::format_from_name(o->format), o->files, opt);
      }
      const auto registry = runtime::builtin_registry();
      std::vector<runtime::RawParam> raw = {{"format", o->format, "play-data"},
                                            {"files", o->files, "play-data"},
                                            {"rate", std::to_string(o->rate), "play-data"},
                                            {"loop", o->loop ? "true" : "false", "play-data"},
                                            {"on_error", o->on_error, "play-data"},
                                            {"sensor_id", o->sensor_id, "play-data"}};
      runtime::ResolvedComponent c{"playback", "playback",
                                   registry.find("playback")->info.params.resolve(raw, "play-data")};
      return run_graph(registry, make_config(g), {c}, o->run, nullptr);
    };
  });
}

}  // namespace skelgraph::cli
