// skelgraph bag info|import|export|recover: MCAP recordings without DDS.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>


#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "run_graph.hpp"
#include "skelgraph/runtime/registry.hpp"
#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/json.hpp"
#include "skelgraph/msg/schema.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/playback/bvh.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/recording/info.hpp"
#include "skelgraph/recording/merge.hpp"
#include "skelgraph/recording/session_recorder.hpp"
#include "skelgraph/recording/tick_frames.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/scene/scene_export.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::cli {

namespace {

// A bad file is the user's input: exit 2 with what and where.
template <class F>
auto user_input(F&& f) {
  try {
    return f();
  } catch (const mcap::McapError& e) {
    throw UsageError(e.what());
  } catch (const playback::DataError& e) {
    throw UsageError(e.what());
  }
}


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
    auto d = user_input([&] { return recording::recording_info(f); });
    valid = valid && d["valid"].get<bool>();
    if (!json) print_info(d);
    all.push_back(std::move(d));
  }
  if (json) std::printf("%s\n", (files.size() == 1 ? all[0] : all).dump(2).c_str());
  return valid ? 0 : 1;
}

int import(playback::Format format, const std::vector<std::string>& files, const playback::ReadOptions& opt,
           const std::string& out, mcap::Compression compression, bool json) {
  mcap::WriterOptions wo;
  wo.compression = compression;
  recording::BagWriter bag(out, wo);
  std::uint64_t frames = 0;
  for (const auto& f : files) {
    const auto rec = user_input([&] { return playback::read_recording(format, f, opt); });
    mcap::KeyValues meta = rec.metadata;
    meta["format"] = rec.format;
    meta["source"] = f;
    bag.write_metadata("import", meta);
    for (const auto& s : rec.frames) {
      if (s.stamp_ns < 0) throw UsageError(f + ": negative time stamp " + std::to_string(s.stamp_ns) + " cannot be recorded");
      const auto t = static_cast<std::uint64_t>(s.stamp_ns);
      bag.write(runtime::topics::kSkeletonRaw.name, skeleton::to_msg(s), t, t);
      ++frames;
    }
    if (!json) std::fprintf(stderr, "%s: %zu frames\n", f.c_str(), rec.frames.size());
  }
  bag.close();
  if (json) std::printf("%s\n", nlohmann::json{{"out", out}, {"frames", frames}, {"files", files}}.dump(2).c_str());
  else std::printf("%s: %llu skeletons from %zu file(s)\n", out.c_str(), static_cast<unsigned long long>(frames), files.size());
  return 0;
}

struct MocapOptions {
  std::string file, out, add_to, transform, mapping, units = "cm", frame_id = "world", mocap_id = "mocap", time_points;
  std::optional<double> time_offset;
  bool json = false;
};

// Motion capture (BVH) as ground truth on skelgraph/skeleton/truth, alone or
// added to a copy of a recording (so `eval recording` scores it against the mocap).
int import_bvh(const MocapOptions& o) {
  playback::BvhOptions b;
  b.units_to_m = o.units == "mm" ? 0.001 : o.units == "m" ? 1.0 : o.units == "in" ? 0.0254 : 0.01;
  if (!o.transform.empty()) {
    try {
      b.target_from_mocap = calib::read_transform_file(o.transform, o.mocap_id);
    } catch (const calib::CalibFileError& e) {
      throw UsageError(e.what());
    }
  }
  if (!o.time_points.empty()) b.time_points = user_input([&] { return playback::read_bvh_time_points(o.time_points); });
  if (!o.mapping.empty()) b.joints = user_input([&] { return playback::read_bvh_mapping(o.mapping); });
  b.frame_id = o.frame_id;
  mcap::WriterOptions wo;
  wo.compression = mcap::Compression::Zstd;
  recording::BagWriter bag(o.out, wo);
  std::uint64_t copied = 0;
  std::optional<std::uint64_t> first;
  if (!o.add_to.empty()) {
    const mcap::Reader reader = user_input([&] { return mcap::Reader(o.add_to); });
    copied = user_input([&] {
      return mcap::copy_messages(
          reader, bag.mcap(),
          [](const mcap::Channel& ch) { return ch.topic != runtime::topics::kSkeletonTruth.name; },  // replaced by the mocap
          [&](const mcap::Channel&, const mcap::Schema*, const mcap::Message& m) {
            if (!first || m.log_time < *first) first = m.log_time;
          });
    });
  }
  b.time_offset_s = o.time_offset ? *o.time_offset : first ? 1e-9 * static_cast<double>(*first) : 0.0;
  const auto rec = user_input([&] { return playback::bvh_recording(o.file, playback::read_bvh(o.file), b); });
  for (const auto& s : rec.frames) {
    if (s.stamp_ns < 0) throw UsageError(o.file + ": negative time stamp; give --time-offset");
    const auto t = static_cast<std::uint64_t>(s.stamp_ns);
    bag.write(runtime::topics::kSkeletonTruth.name, skeleton::to_msg(s), t, t);
  }
  bag.write_metadata("mocap", {{"source", o.file}, {"units", o.units}, {"frame_id", o.frame_id}, {"joints", rec.metadata.at("joints")}});
  bag.close();
  const double span = rec.frames.size() > 1 ? 1e-9 * static_cast<double>(rec.frames.back().stamp_ns - rec.frames.front().stamp_ns) : 0.0;
  if (o.json)
    std::printf("%s\n", nlohmann::json{{"out", o.out}, {"truth_frames", rec.frames.size()}, {"span_s", span}, {"copied", copied},
                                       {"time_offset_s", b.time_offset_s}}
                            .dump(2)
                            .c_str());
  else
    std::printf("%s: %zu mocap frames (%.1f s) on %s%s\n", o.out.c_str(), rec.frames.size(), span,
                runtime::topics::kSkeletonTruth.name,
                o.add_to.empty() ? "" : (", with the " + std::to_string(copied) + " messages of " + o.add_to).c_str());
  return 0;
}

// The recording with the cell as a 3-D scene for Foxglove/Lichtblick added (scene_export.hpp).
int export_scene(const std::string& file, const std::string& out, const std::string& compression, bool json) {
  mcap::WriterOptions w;
  w.compression = *mcap::compression_from_name(compression);
  Progress progress(!json);
  const auto r = user_input([&] {
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

// generic: our lossless CSV (reads back with the generic reader). csv: plain
// numeric columns per sensor, one line per frame, as the thesis's per-Kinect
// text logs were: time, person, then x, y, z, confidence of every joint.
int export_bag(const std::string& file, const std::string& format, const std::string& dir, bool json) {
  const mcap::Reader reader = user_input([&] { return mcap::Reader(file); });
  std::map<std::string, playback::Recording> by_stream;  // "<topic tail>_<sensor>"
  user_input([&] {
    reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
      if (schema == nullptr || schema->name != msg::MessageTraits<msg::Skeleton>::name) return;
      auto s = skeleton::from_msg(msg::from_cdr<msg::Skeleton>(m.data.data(), m.data.size()));
      const auto tail = ch.topic.substr(ch.topic.rfind('/') + 1);
      auto& rec = by_stream[recording::file_safe(tail + "_" + s.sensor_id)];
      rec.format = "generic";
      rec.metadata["topic"] = ch.topic;
      rec.metadata["source"] = file;
      rec.frames.push_back(std::move(s));
    });
    return 0;
  });
  std::filesystem::create_directories(dir);
  nlohmann::json written = nlohmann::json::object();
  for (auto& [name, rec] : by_stream) {
    const auto path = std::filesystem::path(dir) / (name + ".csv");
    std::ofstream out(path);
    if (!out) throw std::runtime_error("cannot write " + path.string());
    if (format == "generic") {
      playback::write_generic_csv(rec, out);
    } else {
      out << "stamp_ns,time_s,person_id,frame_number";
      for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
        const std::string n = skeleton::joint_name(skeleton::joint_at(j));
        out << "," << n << "_x," << n << "_y," << n << "_z," << n << "_conf";
      }
      out << "\n" << std::setprecision(9);
      const auto t0 = rec.frames.empty() ? 0 : rec.frames.front().stamp_ns;
      for (const auto& s : rec.frames) {
        out << s.stamp_ns << "," << static_cast<double>(s.stamp_ns - t0) * 1e-9 << "," << s.person_id << ","
            << s.frame_number;
        for (const auto& j : s.joints) {
          out << "," << j.position.x() << "," << j.position.y() << "," << j.position.z() << "," << j.confidence;
        }
        out << "\n";
      }
    }
    if (!out.flush()) throw std::runtime_error("error writing " + path.string());
    written[path.string()] = rec.frames.size();
  }
  if (json) std::printf("%s\n", nlohmann::json{{"files", written}}.dump(2).c_str());
  else for (const auto& [p, n] : written.items()) std::printf("%s: %s frames\n", p.c_str(), n.dump().c_str());
  return 0;
}

int recover(const std::string& in, const std::string& out, bool json) {
  const auto rep = user_input([&] { return mcap::recover(in, out); });
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
  const auto r = user_input([&] {
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
  return user_input([&] { return run_components(g, {{kind, kind, raw}}, ro); });
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
      return user_input([&] { return run_components(g, list, r->run); });
    };
  });

  auto* i = bag->add_subcommand("info", "What a recording holds: duration, topics with counts and rates, ticks, sessions, "
                                        "metadata, attachments, which indexes it has; exit 1 if a file is damaged");
  i->add_option("files", o->files, "MCAP file(s)")->required()->check(CLI::ExistingFile);
  i->add_flag("--json", o->json, "machine-readable output (several files: an array)");
  i->callback([o, &run] { run = [o] { return info(o->files, o->json); }; });

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
