// skelgraph sim: the simulator against the thesis's Tables 5.1/5.2 (table),
// a run written to files (export, hand-at-tool: sim/sim_files.hpp), the true
// poses (poses) and synthetic board views (boards: calib/sim_boards.hpp). No DDS.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "cli.hpp"

#include "skelgraph/calib/sim_boards.hpp"
#include "skelgraph/robot/robot_component.hpp"
#include "skelgraph/sim/realism.hpp"
#include "skelgraph/sim/sim_component.hpp"
#include "skelgraph/sim/sim_files.hpp"
#include "skelgraph/sim/simulation.hpp"

namespace skelgraph::cli {

sim::SimConfig sim_config(const std::vector<std::string>& assignments, const char* what,
                          const std::vector<runtime::RawParam>& extra) {
  try {
    return sim::sim_config_from_assignments(assignments, what, extra);
  } catch (const runtime::ParamError& e) {
    throw UsageError(e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

namespace {

// "simulated N of M s" on the progress line.
sim::SimProgress simulated(Progress& progress) {
  return [&progress](double done_s, double total_s) {
    char text[64];
    std::snprintf(text, sizeof text, "simulated %.0f of %.0f s", done_s, total_s);
    progress(text, done_s >= total_s);
  };
}

int table(const sim::RealismOptions& opt, bool json, bool check) {
  Progress progress;
  const auto cells = sim::compare_with_thesis(
      opt, [&](const std::string& profile, const std::string& s) { progress("simulating " + profile + " " + s + "..."); });
  progress.done(false);
  nlohmann::json out = nlohmann::json::array();
  int misses = 0;
  if (!json) {
    std::printf("Detection %% (sim / thesis) and mean error of tracked joints, cm (sim / thesis); '*' = outside tolerance\n");
    std::printf("seed %llu, %d repeat(s) of each scenario, one sensor 2 m away\n",
                static_cast<unsigned long long>(opt.seed), opt.repeats);
  }
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const auto& c = cells[i];
    const bool new_profile = i == 0 || cells[i - 1].profile != c.profile;
    const bool new_group = new_profile || cells[i - 1].group != c.group;
    misses += (c.detection_close ? 0 : 1) + (c.error_close ? 0 : 1);
    if (json) {
      out.push_back({{"profile", c.profile}, {"scenario", c.scenario}, {"group", sim::group_names()[c.group]},
                     {"sim_detection_pct", c.sim.detection_pct}, {"thesis_detection_pct", c.thesis.detection_pct},
                     {"sim_error_cm", std::isfinite(c.sim.error_cm) ? nlohmann::json(c.sim.error_cm) : nlohmann::json()},
                     {"thesis_error_cm", c.thesis.error_cm}, {"detection_close", c.detection_close}, {"error_close", c.error_close}});
      continue;
    }
    if (new_profile) {
      std::printf("\n%-6s %-10s", c.profile.c_str(), "group");
      for (const auto& s : sim::kThesisScenarios) std::printf(" | %-21s", s.c_str());
      std::printf("\n");
    }
    if (new_group) std::printf("%-6s %-10s", "", sim::group_names()[c.group]);
    std::printf(" | %3.0f/%3.0f%c %5.1f/%5.1f%c", c.sim.detection_pct, c.thesis.detection_pct, c.detection_close ? ' ' : '*',
                c.sim.error_cm, c.thesis.error_cm, c.error_close ? ' ' : '*');
    if (i + 1 == cells.size() || cells[i + 1].group != c.group || cells[i + 1].profile != c.profile) std::printf("\n");
  }
  const int n = static_cast<int>(2 * cells.size());
  if (json) {
    std::printf("%s\n", nlohmann::json{{"seed", opt.seed}, {"repeats", opt.repeats}, {"cells", n},
                                       {"outside_tolerance", misses}, {"rows", out}}
                            .dump(2)
                            .c_str());
  } else {
    std::printf("\n%d of %d figures outside tolerance (detection: 20 points; error: factor 2 or 6 cm)\n", misses, n);
  }
  return check && misses > 0 ? 1 : 0;
}

// The simulated sensors' true poses as a calibration file.
int write_poses(const std::vector<std::string>& assignments, const std::string& out, bool json) {
  const auto cfg = sim_config(assignments, "sim poses");
  const auto f = calib::true_poses(cfg, "the simulator's true sensor poses (skelgraph sim poses)");
  try {
    calib::write_calib_file(out, f);
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
  if (json) std::printf("%s\n", nlohmann::json{{"out", out}, {"sensors", f.sensors.size()}}.dump(2).c_str());
  else std::printf("%s: %zu sensor pose(s)\n", out.c_str(), f.sensors.size());
  return 0;
}

// Synthetic checkerboard views of the simulated cell to calibrate from
// (calib::write_sim_boards), or the board on a simulated robot's tool
// (calib::write_sim_robot_boards).
struct BoardsOpts {
  calib::RobotBoardsOptions robot;  // robot.boards: the views (without --robot, only those)
  std::vector<std::string> params;
  std::string size = "9x6";
  double square_m = 0.08;
  bool json = false;
};

int write_boards(const BoardsOpts& o) {
  const auto cfg = sim_config(o.params, "sim boards");
  auto b = o.robot.boards;
  try {
    b.board = calib::Board::parse(o.size, o.square_m);
    if (!o.robot.base_text.empty()) {
      auto r = o.robot;
      r.boards = b;
      try {
        r.world_from_base = robot::parse_base(r.base_text);
      } catch (const std::exception& e) {
        throw UsageError(std::string("--robot: ") + e.what());
      }
      const auto s = calib::write_sim_robot_boards(cfg, r);
      if (o.json) {
        std::printf("%s\n", nlohmann::json{{"dir", b.dir}, {"robot_poses", s.robot_poses}, {"views", s.views}, {"images", s.images}}.dump(2).c_str());
      } else {
        std::printf("%s: %zu robot poses, %zu images for %zu sensors; tool poses in tool_poses.yaml, truth in truth.yaml\n",
                    b.dir.c_str(), s.robot_poses, s.images, cfg.sensors.size());
      }
      return 0;
    }
    const auto s = calib::write_sim_boards(cfg, b);
    if (o.json) {
      std::printf("%s\n", nlohmann::json{{"dir", b.dir}, {"sensors", cfg.sensors.size()}, {"views", s.views}, {"images", s.images}}.dump(2).c_str());
    } else {
      for (const auto& [sensor, own] : s.intrinsics_views) {
        std::fprintf(stderr, "%s: %zu shared views, %zu intrinsics views\n", sensor.c_str(), s.views, own);
      }
      std::printf("%s: %zu images for %zu sensors, truth in truth.yaml\n", b.dir.c_str(), s.images, cfg.sensors.size());
    }
  } catch (const calib::CalibError& e) {
    throw UsageError(e.what());
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
  return 0;
}

// A person's hand held at a robot's tool (sim::write_hand_at_tool), for calib robot --hand.
struct HandOpts {
  std::string out;
  std::vector<std::string> params;
  sim::HandAtToolOptions hand;
  bool json = false;
};

int write_hand_at_tool(const HandOpts& o) {
  const auto cfg = sim_config(o.params, "sim hand-at-tool");
  Progress progress(!o.json);
  const auto s = sim::write_hand_at_tool(cfg, o.out, o.hand, simulated(progress));
  const nlohmann::json j{{"out", o.out}, {"duration_s", s.duration_s}, {"robot_states", s.robot_states}, {"raw_skeletons", s.raw_skeletons}};
  if (o.json) std::printf("%s\n", j.dump(2).c_str());
  else std::printf("%s: %.0f s, %zu robot states, %zu sensor skeletons\n", o.out.c_str(), s.duration_s, s.robot_states, s.raw_skeletons);
  return 0;
}

int export_run(const std::vector<std::string>& assignments, const std::string& dir, bool json) {
  const auto cfg = sim_config(assignments, "sim export");
  Progress progress(!json);
  const auto s = sim::export_simulation(cfg, dir, simulated(progress));
  if (json) {
    std::printf("%s\n", nlohmann::json{{"directory", dir}, {"duration_s", s.duration_s}, {"rows", s.files}}.dump(2).c_str());
  } else {
    for (const auto& [name, rows] : s.files.items()) std::printf("%s/%s: %s rows\n", dir.c_str(), name.c_str(), rows.dump().c_str());
  }
  return 0;
}

}  // namespace

void add_sim_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* cmd = app.add_subcommand("sim", "Offline tools of the work-cell simulator");
  cmd->require_subcommand(1);
  struct Opts {
    sim::RealismOptions realism;
    bool json = false;
    bool check = false;
  };
  auto o = std::make_shared<Opts>();
  auto* t = cmd->add_subcommand("table", "Compare the simulator with the thesis's Tables 5.1/5.2 (one sensor)");
  t->add_option("--seed", o->realism.seed, "random seed");
  t->add_option("--repeats", o->realism.repeats, "repeats of each scenario")->check(CLI::Range(1, 100));
  t->add_option("--noise-scale", o->realism.noise_scale, "scale of the tracker's noise")->check(kNonNegative);
  t->add_flag("--json", o->json, "machine-readable output");
  t->add_flag("--check", o->check, "exit 1 if any figure is outside tolerance");
  t->callback([o, &run] { run = [o] { return table(o->realism, o->json, o->check); }; });

  struct ExportOpts {
    std::string dir;
    std::vector<std::string> params;
    bool json = false;
  };
  auto ho = std::make_shared<HandOpts>();
  auto* h = cmd->add_subcommand("hand-at-tool", "Simulate a person's hand held at a robot's tool, written as a recording "
                                                "(skeletons, truth, true poses, the tool's positions) for calib robot --hand");
  h->add_option("recording", ho->out, "MCAP file to write")->required();
  h->add_option("-p,--param", ho->params, "sim parameter as KEY=VALUE (scenario, layout, sensor_count, seed, ...)");
  h->add_option("--contact-cm", ho->hand.contact_cm, "the tool point beyond the hand joint, along the forearm (default 3)")->check(kNonNegative);
  h->add_option("--tool-noise", ho->hand.tool_noise_mm, "error of the reported tool positions, mm per axis (sd; default 1)")->check(kNonNegative);
  h->add_flag("--json", ho->json, "machine-readable summary");
  h->callback([ho, &run] { run = [ho] { return write_hand_at_tool(*ho); }; });

  auto e = std::make_shared<ExportOpts>();
  auto* x = cmd->add_subcommand("export", "Run a simulation offline and write it as generic CSV (truth, each sensor, phases), and the truth as motion capture (truth.bvh)");
  x->add_option("directory", e->dir, "output directory (created)")->required();
  x->add_option("-p,--param", e->params, "sim parameter as KEY=VALUE, as in `skelgraph components` (repeatable)");
  x->add_flag("--json", e->json, "machine-readable summary");
  x->callback([e, &run] { run = [e] { return export_run(e->params, e->dir, e->json); }; });

  auto po = std::make_shared<ExportOpts>();
  auto* ps = cmd->add_subcommand("poses", "Write the simulated sensors' true poses as a calibration file (YAML)");
  ps->add_option("file", po->dir, "calibration file to write")->required();
  ps->add_option("-p,--param", po->params, "sim parameter as KEY=VALUE (sensor_count, sensors)");
  ps->add_flag("--json", po->json, "machine-readable summary");
  ps->callback([po, &run] { run = [po] { return write_poses(po->params, po->dir, po->json); }; });

  auto bo = std::make_shared<BoardsOpts>();
  auto* b = cmd->add_subcommand("boards", "Render synthetic checkerboard views (colour + depth) of the simulated cell to calibrate from");
  b->add_option("directory", bo->robot.boards.dir, "output directory (created)")->required();
  b->add_option("-p,--param", bo->params, "sim parameter as KEY=VALUE (sensor_count, sensors)");
  b->add_option("--views", bo->robot.boards.views, "views every sensor sees (default 20)")->check(CLI::Range(3, 500));
  b->add_option("--intrinsics-views", bo->robot.boards.intrinsics_views, "views per sensor for its intrinsics (default 15)")->check(CLI::Range(3, 500));
  b->add_option("--board", bo->size, "inner corners COLSxROWS (default 9x6)");
  b->add_option("--square", bo->square_m, "square size, m (default 0.08)")->check(kPositive);
  b->add_option("--grey-noise", bo->robot.boards.grey_noise, "image noise, grey levels (default 2)")->check(kNonNegative);
  b->add_option("--depth-noise", bo->robot.boards.depth_noise, "scale of Kinect-like depth noise (default 1)")->check(kNonNegative);
  b->add_option("--seed", bo->robot.boards.seed, "random seed");
  b->add_option("--robot", bo->robot.base_text,
                "X,Y,Z,YAW: the board on the tool of a simulated UR5e whose base stands there (as the robot component's "
                "`base`), --views poses facing each sensor, and the tool poses the robot reports (for calib robot)");
  b->add_option("--tool-noise", bo->robot.tool_noise_mm, "with --robot: error of the reported tool positions, mm per axis (sd; default 1)")
      ->check(kNonNegative);
  b->add_option("--tool-noise-deg", bo->robot.tool_noise_deg, "with --robot: error of the reported tool orientations, deg (sd; default 0.1)")
      ->check(kNonNegative);
  b->add_flag("--json", bo->json, "machine-readable summary");
  b->callback([bo, &run] { run = [bo] { return write_boards(*bo); }; });
}

}  // namespace skelgraph::cli
