// skelgraph bag record|play|info|merge|recover and skelgraph view (import, import-bvh,
// export: cmd_bag_convert.cpp).

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "cmd_bag.hpp"
#include "run_graph.hpp"
#include "skelgraph/recording/info.hpp"
#include "skelgraph/recording/merge.hpp"

namespace skelgraph::cli {

namespace {
using bag_cmd::file_input;

void print_info(const nlohmann::json& d) {
  const auto u = [](const nlohmann::json& v) { return static_cast<unsigned long long>(v.get<std::uint64_t>()); };
  std::printf("file:      %s (%llu bytes, %s)\n", d["file"].get<std::string>().c_str(), u(d["size_bytes"]),
              d["valid"].get<bool>() ? "valid" : ("INVALID: " + d["problem"].get<std::string>()).c_str());
  std::printf("duration:  %.3f s, %llu messages in %llu chunks, %llu attachments, %llu ticks\n", d["duration_s"].get<double>(),
              u(d["messages"]), u(d["chunks"]), u(d["attachments"]), u(d["ticks"]));
  for (const auto& n : d["notes"]) std::printf("note:      %s\n", n.get<std::string>().c_str());
  for (const auto& t : d["topics"]) {
    std::printf("  %-32s %-34s %8llu msgs %8.2f Hz\n", t["topic"].get<std::string>().c_str(),
                t["type"].get<std::string>().c_str(), u(t["count"]), t["rate_hz"].get<double>());
  }
  for (const auto& [h, n] : d["ticks_acked_by_host"].items()) std::printf("  host %-20s %8llu ticks acked\n", h.c_str(), u(n));
  for (const auto& [h, c] : d["clock_offsets"].items()) {
    std::printf("  clock %-19s offset %+.3f ms, drift %+.1f ppm, rtt %.3f ms\n", h.c_str(),
                c["offset_ns"].get<double>() * 1e-6, c["drift_ppm"].get<double>(), c["rtt_ns"].get<double>() * 1e-6);
  }
  for (const auto& [k, n] : d["skeletons_per_sensor"].items()) std::printf("  skeletons %-40s %8llu\n", k.c_str(), u(n));
  for (const auto& [k, n] : d["ticks_with_frames_of"].items()) {
    std::printf("  frames at ticks %-34s %8llu of %llu ticks\n", k.c_str(), u(n), u(d["tick_records"]));
  }
  for (const auto& m : d["metadata"]) {
    std::printf("  metadata %s:", m["name"].get<std::string>().c_str());
    for (const auto& [k, v] : m["values"].items()) std::printf(" %s=%s", k.c_str(), v.get<std::string>().c_str());
    std::printf("\n");
  }
}

// One file: its object (--json) or text; several: an array, or each in turn. Exit 1 if any is damaged.
int info(const std::vector<std::string>& files, bool json) {
  nlohmann::json all = nlohmann::json::array();
  bool valid = true;
  for (const auto& f : files) {
    auto d = file_input([&] { return recording::recording_info(f); });
    valid = valid && d["valid"].get<bool>();
    if (!json) print_info(d);
    all.push_back(std::move(d));
  }
  if (json) std::printf("%s\n", (files.size() == 1 ? all[0] : all).dump(2).c_str());
  return valid ? 0 : 1;
}

int recover(const std::string& in, const std::string& out, bool json) {
  const auto rep = file_input([&] { return mcap::recover(in, out); });
  const double lost = rep.input_size > 0 ? 100.0 * static_cast<double>(rep.input_size - rep.bytes_read) / rep.input_size : 0;
  if (json) {
    std::printf("%s\n", nlohmann::json{{"in", in},
                                       {"out", out},
                                       {"messages", rep.messages},
                                       {"chunks", rep.chunks},
                                       {"bytes_read", rep.bytes_read},
                                       {"input_size", rep.input_size},
                                       {"stopped_because", rep.stopped_because}}
                            .dump(2)
                            .c_str());
  } else {
    std::printf("%s: %llu messages in %llu chunks recovered from %s (%.1f %% of its bytes unusable)\n", out.c_str(),
                static_cast<unsigned long long>(rep.messages), static_cast<unsigned long long>(rep.chunks), in.c_str(), lost);
    if (!rep.stopped_because.empty()) std::printf("stopped: %s\n", rep.stopped_because.c_str());
  }
  return 0;
}

// Several hosts' recordings of one session onto the sync master's timeline
// (recording/merge.hpp: streaming, in bounded memory).
int merge(const std::vector<std::string>& files, const std::string& out_path, mcap::Compression compression,
          double max_age_ms, bool json) {
  recording::MergeOptions options;
  options.compression = compression;
  options.max_age_ms = max_age_ms;
  const auto r = file_input([&] {
    try {
      return recording::merge_recordings(files, out_path, options);
    } catch (const recording::MergeError& e) {
      throw UsageError(e.what());
    }
  });
  nlohmann::json inputs = nlohmann::json::object();
  for (const auto& in : r.inputs)
    inputs[in.file] = {{"host", in.host}, {"offset_ns", in.offset_ns}, {"drift_ppm", in.drift_ppm}, {"estimated", in.estimated}};
  const nlohmann::json report{{"out", out_path},
                              {"messages", r.messages},
                              {"duplicates_dropped", r.duplicates_dropped},
                              {"inputs", inputs},
                              {"ticks_acked_by_host", r.ticks_acked_by_host},
                              {"tick_records", r.tick_records},
                              {"frames_per_tick", r.tick_records > 0 ? static_cast<double>(r.frames_at_ticks) / r.tick_records : 0.0},
                              {"out_of_order", r.out_of_order},
                              {"peak_held_messages", r.peak_held}};
  if (json) std::printf("%s\n", report.dump(2).c_str());
  else std::printf("%s: %llu messages (%llu duplicates dropped) from %zu recordings; %llu ticks, %.1f frames each\n",
                   out_path.c_str(), static_cast<unsigned long long>(r.messages),
                   static_cast<unsigned long long>(r.duplicates_dropped), files.size(),
                   static_cast<unsigned long long>(r.tick_records), report["frames_per_tick"].get<double>());
  return 0;
}

}  // namespace

// Runs one component of `kind` with parameters given as text.
int run_component(GlobalOptions& g, const std::string& kind, const std::vector<runtime::RawParam>& raw,
                  const RunOptions& ro) {
  return file_input([&] { return run_components(g, {{kind, kind, raw}}, ro); });
}

void add_bag_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto* bag = app.add_subcommand("bag", "MCAP recordings: record, play, info, merge, import, export, recover");
  bag->require_subcommand(1);
  struct Opts {
    std::string file, out, format = "csv", compression = "zstd", on_error = "stop", sensor_id;
    std::vector<std::string> files;
    double max_age_ms = 100;
    bool json = false, scene = false;
  };
  auto o = std::make_shared<Opts>();

  struct RecOpts {
    std::string dir = "recordings", label = "manual", compression = "zstd", host;
    std::vector<std::string> topics;
    bool now = false, depth = false, scene = false;
    double rate = 1.0;
    bool loop = false;
    RunOptions run;
  };
  auto r = std::make_shared<RecOpts>();
  auto* rec = bag->add_subcommand("record", "Record skelgraph topics to MCAP: a file per sync session (START..STOP), or from now with --now");
  rec->add_option("--dir", r->dir, "directory for the files");
  rec->add_flag("--now", r->now, "record from now until stopped, without waiting for the sync topic");
  rec->add_option("--label", r->label, "session label with --now");
  rec->add_option("--topics", r->topics, "topics to record (default: every skelgraph topic but depth)");
  rec->add_flag("--include-depth", r->depth, "also record skelgraph/depth");
  rec->add_flag("--scene", r->scene, "also write the cell as a 3-D scene for Foxglove/Lichtblick into each file (as bag export --scene)");
  rec->add_option("--compression", r->compression, "chunk compression")->check(CLI::IsMember({"none", "lz4", "zstd"}));
  rec->add_option("--host", r->host, "host name for file names and acks (default: this host)");
  add_run_options(*rec, r->run);
  add_dds_options(*rec, g);
  rec->callback([r, &g, &run] {
    run = [r, &g] {
      std::vector<runtime::RawParam> raw = {{"directory", r->dir, "bag record"},
                                            {"now", r->now ? "true" : "false", "bag record"},
                                            {"label", r->label, "bag record"},
                                            {"include_depth", r->depth ? "true" : "false", "bag record"},
                                            {"compression", r->compression, "bag record"},
                                            {"host", r->host, "bag record"},
                                            {"scene", r->scene ? "true" : "false", "bag record"}};
      if (!r->topics.empty()) raw.push_back({"topics", r->topics, "bag record"});
      return run_component(g, "recorder", raw, r->run);
    };
  });

  auto* pl = bag->add_subcommand("play", "Republish a recording with its original timing, topics and keys");
  pl->add_option("file", o->file, "MCAP file")->required()->check(CLI::ExistingFile);
  pl->add_option("--rate", r->rate, "1 = as recorded, 2 = twice as fast")->check(kPositive);
  pl->add_flag("--loop", r->loop, "start again at the end");
  pl->add_option("--topics", r->topics, "only these topics (default: all but skelgraph/status)");
  add_run_options(*pl, r->run);
  add_dds_options(*pl, g);
  pl->callback([o, r, &g, &run] {
    run = [o, r, &g] {
      std::vector<runtime::RawParam> raw = {{"file", o->file, "bag play"},
                                            {"rate", std::to_string(r->rate), "bag play"},
                                            {"loop", r->loop ? "true" : "false", "bag play"}};
      if (!r->topics.empty()) raw.push_back({"topics", r->topics, "bag play"});
      return run_component(g, "bag_player", raw, r->run);
    };
  });

  struct ViewOpts {
    std::string address = "127.0.0.1";
    std::string credentials;
    int port = 8080;
    double rate = 1.0;
    bool paused = false, loop = false;
  };
  auto v = std::make_shared<ViewOpts>();
  auto* view = app.add_subcommand(
      "view", "A recording in the browser: plays it (bag_player, held at the end) with the viewer; the page has a timeline (seek, speed, pause, step)");
  view->add_option("file", o->file, "MCAP file")->required()->check(CLI::ExistingFile);
  view->add_option("--address", v->address,
                   "where the page is served (0.0.0.0: every interface; anything but loopback needs --credentials)");
  view->add_option("--credentials", v->credentials,
                   "the cell's credentials (skelgraph security init, viewer): HTTPS, and a viewer certificate or token "
                   "for every request");
  view->add_option("--port", v->port, "TCP port of the page (0: any free port)")->check(CLI::Range(0, 65535));
  view->add_option("--rate", v->rate, "speed at start: 1 = as recorded")->check(kPositive);
  view->add_flag("--paused", v->paused, "start paused");
  view->add_flag("--loop", v->loop, "start again at the end");
  add_run_options(*view, r->run);
  add_dds_options(*view, g);
  view->callback([o, v, r, &g, &run] {
    run = [o, v, r, &g] {
      const auto b = [](bool x) { return std::string(x ? "true" : "false"); };
      const std::vector<ComponentRun> list{
          {"player", "bag_player",
           {{"file", o->file, "view"},
            {"rate", std::to_string(v->rate), "view"},
            {"paused", b(v->paused), "view"},
            {"loop", b(v->loop), "view"},
            {"hold_at_end", "true", "view"}}},
          {"viewer", "viewer",
           {{"address", v->address, "view"},
            {"port", std::to_string(v->port), "view"},
            {"credentials", v->credentials, "view"}}}};
      return file_input([&] { return run_components(g, list, r->run); });
    };
  });

  auto* i = bag->add_subcommand("info", "What a recording holds: duration, topics with counts and rates, ticks, sessions, "
                                        "metadata, attachments, which indexes it has; exit 1 if a file is damaged");
  i->add_option("files", o->files, "MCAP file(s)")->required()->check(CLI::ExistingFile);
  i->add_flag("--json", o->json, "machine-readable output (several files: an array)");
  i->callback([o, &run] { run = [o] { return info(o->files, o->json); }; });

  bag_cmd::add_convert_commands(*bag, run);

  auto* mg = bag->add_subcommand("merge", "Several hosts' recordings of a session onto the sync master's timeline");
  mg->add_option("files", o->files, "recordings (one per host)")->required()->check(CLI::ExistingFile);
  mg->add_option("--out", o->out, "MCAP file to write")->required();
  mg->add_option("--compression", o->compression, "chunk compression")->check(CLI::IsMember({"none", "lz4", "zstd"}));
  mg->add_option("--max-age-ms", o->max_age_ms,
                 "a frame older than this at a tick is not associated with it (default 100 ms, 3 frames at 30 Hz)")
      ->check(CLI::PositiveNumber);
  mg->add_flag("--json", o->json, "machine-readable summary");
  mg->callback([o, &run] {
    run = [o] {
      return merge(o->files, o->out, *mcap::compression_from_name(o->compression), o->max_age_ms, o->json);
    };
  });

  auto* rc = bag->add_subcommand("recover", "Salvage every complete chunk of a recording whose writer was killed");
  rc->add_option("file", o->file, "damaged MCAP file")->required()->check(CLI::ExistingFile);
  rc->add_option("--out", o->out, "MCAP file to write")->required();
  rc->add_flag("--json", o->json, "machine-readable summary");
  rc->callback([o, &run] { run = [o] { return recover(o->file, o->out, o->json); }; });
}

}  // namespace skelgraph::cli
