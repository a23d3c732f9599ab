// skelgraph eval recording|live and skelgraph fuse: recordings scored against
// their truth and fused offline (eval/recording.hpp); the eval command's
// options (eval sim itself: cmd_eval_sim.cpp).

#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "eval_sim.hpp"
#include "run_graph.hpp"
#include "skelgraph/eval/recording.hpp"
#include "skelgraph/eval/report.hpp"
#include "skelgraph/fusion/fuser.hpp"

namespace skelgraph::cli {

namespace {

struct FileOptions : eval::RecordingOptions {
  std::string file, out, report_dir, csv;
  bool json = false;
};

// A long recording's progress on stderr.
eval::ProgressFn progress_of(Progress& p) {
  return [&p](const std::string& text) { p(text); };
}

// skelgraph eval FILE: single sensors and every method, against the truth in the recording if it
// has one; bone-length steadiness and completeness either way.
int eval_file(const FileOptions& o) {
  Progress progress;
  const auto scored = user_input<eval::RecordingError>(
      [&] { return eval::score_recording(o.file, o, !o.report_dir.empty(), progress_of(progress)); });
  progress.done(false);
  const auto& in = scored.in;
  const auto& r = scored.result;
  std::string report_path;
  if (!o.report_dir.empty()) {
    std::filesystem::create_directories(o.report_dir);
    const auto name = std::filesystem::path(o.file).stem().string();
    report_path = eval::write_report_page(o.report_dir, "skelgraph: " + name,
                                    eval::report_section(o.report_dir, name, name, r, "right_hand"));
  }
  nlohmann::json j = scored.summary;
  if (!report_path.empty()) j["report"] = report_path;
  if (!o.csv.empty()) eval::write_text_file(o.csv, eval::csv_header() + eval::csv_rows(o.file, r));
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("## %s\n\n%llu raw skeletons from %zu sensor(s), %llu truth skeletons, %llu live fused skeletons, "
                "%llu output ticks (%s)\n",
                o.file.c_str(), static_cast<unsigned long long>(in.raw), in.poses.size(),
                static_cast<unsigned long long>(in.truth), static_cast<unsigned long long>(in.fused),
                static_cast<unsigned long long>(r.ticks), in.ticks.empty() ? "30 Hz" : "the recording's sync ticks");
    if (!r.has_truth) std::printf("No ground truth in the recording: detection and error columns are empty; "
                                  "upper-body completeness and bone-length SD need none.\n");
    if (in.fused > 0) std::printf("'live <id>': what a fusion component published live, as received by the recorder "
                                  "(scored at each tick against its latest output, so one tick behind).\n");
    print_table(o.file, r);
    if (!report_path.empty()) std::printf("\nreport: %s\n", report_path.c_str());
  }
  return 0;
}

// skelgraph eval live: what is on the domain now (raw skeletons, calibration,
// sync ticks, truth and fused skeletons if published) recorded for a while
// by a recorder in this process, then scored as `eval recording` scores a
// file. The recording is kept, so the figures can be checked and re-run.
struct LiveOptions {
  FileOptions score;      // methods, --json, --report, --csv (file: the recording made)
  double duration = 30.0;  // s
  std::string dir;         // where the recording goes (default: a fresh directory under the temp dir)
};

int eval_live(const LiveOptions& o, GlobalOptions& g) {
  std::string dir = o.dir;
  if (dir.empty()) {
    std::string t = (std::filesystem::temp_directory_path() / "skelgraph-eval-live-XXXXXX").string();
    if (mkdtemp(t.data()) == nullptr)
      throw std::runtime_error("cannot make a directory " + t + ": " + std::strerror(errno) + " (give one with --dir)");
    dir = t;
  }
  const auto config = make_config(g);
  std::fprintf(stderr, "recording the skeleton topics on domain %d (profile %s) for %.0f s into %s (Ctrl-C ends it sooner)\n",
               config.domain, config.profile.c_str(), o.duration, dir.c_str());
  RunOptions ro;
  ro.duration_s = o.duration;
  std::string file;
  const int rc = run_components(
      g,
      {{"eval_recorder", "recorder",
        {{"directory", dir, "eval live --dir"}, {"now", "true", "eval live"}, {"label", "eval_live", "eval live"}}}},
      ro, [&](runtime::Graph& graph, nlohmann::json&) { file = recorded_file(graph); });
  if (rc != 0) return rc;
  if (file.empty()) throw std::runtime_error("the recorder wrote no file into " + dir);
  std::fprintf(stderr, "scoring %s\n", file.c_str());
  FileOptions f = o.score;
  f.file = file;
  try {
    return eval_file(f);
  } catch (const UsageError& e) {
    // Most likely nothing (or no poses) came while it recorded: say where it listened.
    throw UsageError(std::string(e.what()) + " (recorded on domain " + std::to_string(config.domain) + ", profile " +
                     config.profile + ", for " + std::to_string(static_cast<int>(o.duration)) +
                     " s: is the cell running there?)");
  }
}

// skelgraph fuse IN --out OUT: the recording with fused skeletons added on
// skelgraph/skeleton/fused (sensor_id "fused", or "fused_<method>" for several).
int fuse_file(const FileOptions& o) {
  Progress progress;
  const auto j =
      user_input<eval::RecordingError>([&] { return eval::fuse_recording(o.file, o.out, o, progress_of(progress)); });
  progress.done(false);
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%s: %llu fused skeletons (%s) added to %llu messages of %s\n", o.out.c_str(),
                static_cast<unsigned long long>(j["fused"].get<std::uint64_t>()), j["methods"].dump().c_str(),
                static_cast<unsigned long long>(j["copied"].get<std::uint64_t>()), o.file.c_str());
  }
  return 0;
}

}  // namespace

RecordingReport eval_recording_section(const std::string& file, const std::string& report_dir, const std::string& title) {
  FileOptions o;
  o.file = file;
  const auto scored = user_input<eval::RecordingError>([&] { return eval::score_recording(o.file, o, true); });
  std::filesystem::create_directories(report_dir);
  return {scored.summary, eval::report_section(report_dir, "live", title, scored.result, "right_hand")};
}

namespace {
// The fusion options every command here shares.
void add_fusion_options(CLI::App* cmd, std::vector<std::string>& methods, double& delay_ms, double& max_age_ms,
                        const std::string& methods_help) {
  cmd->add_option("--methods,--method", methods, methods_help)->delimiter(',')->check(CLI::IsMember(fusion::method_names()));
  cmd->add_option("--delay-ms", delay_ms, "fuse this far behind the newest data (room to interpolate)")->check(kNonNegative);
  cmd->add_option("--max-age-ms", max_age_ms, "samples older than this are not fused")->check(kPositive);
}
}  // namespace

void add_fuse_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto o = std::make_shared<FileOptions>();
  auto* f = app.add_subcommand("fuse", "Fuse a recording's raw skeletons offline (as the fusion component would live)");
  f->add_option("file", o->file, "MCAP recording with skelgraph/skeleton/raw and skelgraph/calibration")
      ->required()
      ->check(CLI::ExistingFile);
  f->add_option("--out", o->out, "MCAP file to write: the input plus skelgraph/skeleton/fused")->required();
  add_fusion_options(f, o->methods, o->delay_ms, o->max_age_ms,
                     "fusion method(s); several: sensor_id fused_<method> each (default kalman)");
  f->add_flag("--json", o->json, "machine-readable summary");
  f->add_flag("--shared-frame", o->shared_frame, "the sensors' skeletons are already in one frame (e.g. KinectMultiTrack): no poses needed");
  f->add_option("--calibration", o->calibration, "sensor poses from this calibration file (YAML) instead of the recording's")
      ->check(CLI::ExistingFile);
  f->callback([o, &run] {
    if (o->methods.empty()) o->methods = {"kalman"};
    run = [o] { return fuse_file(*o); };
  });
}

// Prediction and scoring at the time of use, the same for every eval command.
void add_time_of_use_options(CLI::App* s, double& predict_ms, double& use_delay_ms) {
  s->add_option("--predict-ms", predict_ms,
                "kalman: predict each joint this far past the fusion time (the trackers' delay plus the consumer's)")
      ->check(CLI::Range(0.0, 1000.0));
  s->add_option("--use-delay-ms", use_delay_ms,
                "score every stream against the truth this long after each output: where the person is when a "
                "consumer uses it, e.g. the measured pipeline delay (bench/latency_bench.sh) plus the consumer's "
                "cycle (default 0: at the output's own time)")
      ->check(CLI::Range(0.0, 1000.0));
}

void add_eval_command(CLI::App& app, GlobalOptions& g, Action& run) {
  auto* ev = app.add_subcommand("eval", "Score single sensors and fusion methods against ground truth");
  ev->require_subcommand(1);
  auto o = std::make_shared<SimEvalOptions>();
  auto* s = ev->add_subcommand("sim", "Simulated scenarios through every fusion method (no DDS, as fast as the CPU allows)");
  s->add_option("-p,--param", o->params, "simulator parameter NAME=VALUE (as the sim component's; e.g. sensor_count=2)");
  s->add_option("--scenarios", o->scenarios, "scenarios to run (default: the thesis's seven)")->delimiter(',');
  s->add_option("--layouts", o->layouts,
                "sensor layouts LAYOUT:SENSORS (quarters, ring, one_side, corners; e.g. quarters:2,ring:4,corners:4), each "
                "with every scenario, a section each in the tables and the report")
      ->delimiter(',');
  add_fusion_options(s, o->methods, o->delay_ms, o->max_age_ms, "fusion methods (default: all)");
  add_time_of_use_options(s, o->predict_ms, o->use_delay_ms);
  s->add_flag("--json", o->json, "machine-readable results");
  s->add_option("--source", o->source,
                "raw skeletons from: tracker (the simulator's tracker model) or depth (rendered depth images through "
                "the open depth tracker, one per sensor) or depth-merged (one tracker fitting every sensor's points at once)")
      ->check(CLI::IsMember({"tracker", "depth", "depth-merged"}));
  s->add_option("--depth-size", o->depth_size, "depth: image size (160x120, 320x240, 640x480)");
  s->add_option("--girth", o->girth, "depth: the simulated people's build (1: the renderer's standard; 0.85 slim, 1.25 stout)")
      ->check(CLI::Range(0.5, 2.0));
  s->add_option("--report", o->report_dir,
                "also write DIR/report.html (tables, inline SVG plots), each plot as SVG, each table as CSV "
                "(DIR/<scenario>.csv, all of them in DIR/results.csv)");
  s->add_option("--csv", o->csv, "also write the tables as CSV to this file (a row per scenario and stream)");
  s->callback([o, &run] { run = [o] { return eval_sim(*o); }; });

  auto fo = std::make_shared<FileOptions>();
  auto* r = ev->add_subcommand("recording", "A recording's single sensors and every fusion method (truth if recorded)");
  r->add_option("file", fo->file, "MCAP recording with skelgraph/skeleton/raw, skelgraph/calibration (and truth)")
      ->required()
      ->check(CLI::ExistingFile);
  add_fusion_options(r, fo->methods, fo->delay_ms, fo->max_age_ms, "fusion methods (default: all)");
  add_time_of_use_options(r, fo->predict_ms, fo->use_delay_ms);
  r->add_flag("--json", fo->json, "machine-readable results");
  r->add_flag("--shared-frame", fo->shared_frame, "the sensors' skeletons are already in one frame (e.g. KinectMultiTrack): no poses needed");
  r->add_option("--calibration", fo->calibration, "sensor poses from this calibration file (YAML) instead of the recording's")
      ->check(CLI::ExistingFile);
  r->add_option("--report", fo->report_dir,
                "also write DIR/report.html (table, inline SVG plots), each plot as SVG and the table as CSV");
  r->add_option("--csv", fo->csv, "also write the table as CSV to this file (a row per stream)");
  r->callback([fo, &run] { run = [fo] { return eval_file(*fo); }; });

  auto lo = std::make_shared<LiveOptions>();
  auto* l = ev->add_subcommand("live",
                               "What a running cell publishes now (raw skeletons, poses, sync ticks; truth and fused "
                               "skeletons if published), recorded for a while and scored as `eval recording` scores a file");
  l->add_option("--duration", lo->duration, "seconds to record (Ctrl-C ends it sooner)")->check(kPositive);
  l->add_option("--dir", lo->dir, "directory for the recording (kept; default: a new one under the temp directory)");
  add_fusion_options(l, lo->score.methods, lo->score.delay_ms, lo->score.max_age_ms, "fusion methods (default: all)");
  add_time_of_use_options(l, lo->score.predict_ms, lo->score.use_delay_ms);
  l->add_flag("--json", lo->score.json, "machine-readable results");
  l->add_flag("--shared-frame", lo->score.shared_frame, "the sensors' skeletons are already in one frame: no poses needed");
  l->add_option("--calibration", lo->score.calibration, "sensor poses from this calibration file (YAML) instead of the topic's")
      ->check(CLI::ExistingFile);
  l->add_option("--report", lo->score.report_dir,
                "also write DIR/report.html (table, inline SVG plots), each plot as SVG and the table as CSV");
  l->add_option("--csv", lo->score.csv, "also write the table as CSV to this file (a row per stream)");
  add_dds_options(*l, g);
  l->callback([lo, &g, &run] { run = [lo, &g] { return eval_live(*lo, g); }; });
  add_eval_presence_command(*ev, g, run);
  add_eval_safety_command(*ev, run);
}

}  // namespace skelgraph::cli
