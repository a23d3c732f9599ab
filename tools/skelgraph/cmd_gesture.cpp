// skelgraph gesture train|cv|spot|classify|features|sim: the command line.
// Each subcommand runs in its own file (cmd_gesture_*.cpp) over the gesture
// libraries.

#include <memory>

#include "cmd_gesture.hpp"
#include "skelgraph/gesture/builtin_models.hpp"
#include "skelgraph/sim/scenario.hpp"

namespace skelgraph::cli {

namespace {

using namespace gesture_cmd;

void add_model_options(CLI::App* c, GestureOptions& o);

// --spot and the stream spotter's options (cv, train).
void add_stream_options(CLI::App* c, GestureOptions& o, const std::string& what) {
  c->add_flag("--spot", o.spot_streams, what);
  c->add_option("--window-model", o.stream.model, "--spot: the window classifier, knn (default) or hmm (the --states ... options)")
      ->check(CLI::IsMember({"hmm", "knn"}));
  c->add_option("--knn-k", o.stream.knn_k, "--spot --window-model knn: neighbours (default 5)")->check(CLI::Range(1, 100));
  c->add_option("--window", o.stream.window_s, "--spot: s the classifier looks back (default 1.0)")->check(CLI::Range(0.2, 10.0));
  c->add_option("--step", o.stream.step_s, "--spot: s between windows (default 0.1)")->check(CLI::Range(0.01, 2.0));
  c->add_option("--confirm", o.stream.confirm, "--spot: windows in a row one gesture must win (default 2)")->check(CLI::Range(1, 50));
  c->add_option("--refractory", o.stream.refractory_s, "--spot: s without another event of the same class (default 1.5)")
      ->check(CLI::Range(0.0, 30.0));
  c->add_option_function<std::string>(
       "--near-misses",
       [&o](const std::string& v) {
         try {
           o.stream.near_negative_offsets_s = parse_near_misses(v);
         } catch (const std::invalid_argument& e) {
           throw CLI::ValidationError("--near-misses", e.what());
         }
       },
       "--spot: s from each action point where training windows are garbage too, comma-separated "
       "(default -0.7,-0.5,0.5,0.7), or none")
      ->type_name("S,S,...|none");
}

void add_common(CLI::App* c, GestureOptions& o, bool model_options) {
  c->add_option("inputs", o.inputs, "recordings (files, or directories of .csv files)")->required()->check(CLI::ExistingPath);
  c->add_option("--format", o.format, "input format (default kinder-gator)")->check(CLI::IsMember(playback::format_names()));
  c->add_flag("--json", o.json, "machine-readable output");
  c->add_option("--on-error", o.on_error, "a bad line in an input: stop (default: the file is bad, reported, the others still "
                                          "read, exit 2 at the end) or skip the line")
      ->check(CLI::IsMember({"stop", "skip"}));
  if (!model_options) return;
  c->add_flag("--no-trim", o.no_trim, "keep each clip whole (default: only the part where the arms move)");
  c->add_option("--classes", o.classes, "two-class (point vs garbage; default), five-class, robot (point, stop, come_here, wave, other), or a class-mapping YAML file");
  add_model_options(c, o);
}

// train and cv take the class set's best measured configuration unless one of these is given.
bool any_model_option(CLI::App* c) {
  for (const char* name : {"--features", "--states", "--mixtures", "--covariance", "--init", "--restarts", "--hands"})
    if (c->count(name) > 0) return true;
  return false;
}

void add_model_options(CLI::App* c, GestureOptions& o) {
  c->add_option("--features", o.features, "feature set: thesis8 (the thesis's 8), extended, body, hands, arm (hands and arm need wrists: Kinect v1/v2 "
                "recordings). Default thesis8, 7 states, 1 mixture, full, segments x 1; train and cv on clips without any of "
                "--features --states --mixtures --covariance --init --restarts --hands (nor --sweep): the class set's best measured (two-class, "
                "robot: hands 3/2/diag; five-class: arm 3/1/diag, kmeans x 16; without wrists the default)")
      ->check(CLI::IsMember({"body", "thesis8", "extended", "hands", "arm"}));
  c->add_option("--states", o.states, "HMM states (default 7)")->check(CLI::Range(1, 50));
  c->add_option("--mixtures", o.mixtures, "Gaussians per state (default 1)")->check(CLI::Range(1, 20));
  c->add_option("--garbage-mixtures", o.garbage_mixtures, "Gaussians per state of the garbage model (default: --mixtures)")
      ->check(CLI::Range(1, 20));
  c->add_option("--covariance", o.covariance, "full (default) or diag")->check(CLI::IsMember({"full", "diag"}));
  c->add_option("--hands", o.hands,
                "canonical (default): mirror every clip so its more active arm is the right; augment: also train on mirrored "
                "clips; as-is")
      ->check(CLI::IsMember({"canonical", "augment", "as-is"}));
  c->add_flag("--prefixes", o.prefixes, "also train on each clip's first 50 % and 70 % (for spotting, which decides early)");
  c->add_flag("--per-class", o.per_class, "one model per class (the thesis) instead of one per recorded action");
  c->add_option("--reject-quantile", o.reject_quantile, "share of held-out training clips the rejection threshold may reject (default 0.02; spotting with a garbage class leaves "
                "'no gesture' to it and ignores the threshold)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--iterations", o.iterations, "Baum-Welch iteration cap (default 100)")->check(CLI::Range(1, 10000));
  c->add_option("--init", o.init,
                "first parameters: segments (default: each clip cut into equal parts, a state per part) or kmeans (k-means++ over "
                "all frames, a state per cluster, uniform transitions)")
      ->check(CLI::IsMember({"segments", "kmeans"}));
  c->add_option("--restarts", o.restarts,
                "train each model this many times from different seeds and keep the one that fits its training clips best "
                "(default 1)")
      ->check(CLI::Range(1, 100));
  c->add_option("--tolerance", o.tolerance, "Baum-Welch stops when the log-likelihood per frame gains less (default 1e-4)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--seed", o.seed, "seed for initialisation and folds (default 1)");
  c->add_option("--threads", o.threads, "worker threads (default 2)")->check(CLI::Range(1, 64));
}

// The spotter's settings, the same on `gesture spot` and `gesture sim`.
// Returns --max-target, whose default differs between spot and sim.
CLI::Option* add_spotter_options(CLI::App* c, GestureOptions& o) {
  c->add_option("--hold", o.spot.hold, "s an extended arm is held before pointing is tried (default 0.25)")->check(CLI::Range(0.0, 5.0));
  c->add_option("--aim", o.spot.aim,
                "s of the hold the pointing ray is averaged over, at most: the event goes out when the arm moves again or then "
                "(default 1.5; at most --hold: at once, from a --hold look)")
      ->check(CLI::Range(0.0, 10.0));
  c->add_option("--still-speed", o.spot.still_speed, "m/s below which a hand is still (default 0.25)")->check(CLI::Range(0.01, 5.0));
  c->add_option("--min-raise", o.spot.min_raise,
                "degrees from hanging straight down an extended arm must be raised to count as a pointing hold (default 35)")
      ->check(CLI::Range(0.0, 180.0));
  auto* max_target = c->add_option("--max-target", o.spot.max_target,
                "m: pointing must land on a surface within this of the shoulder (0: any ray, none needed; default 4 in "
                "gesture sim, the simulated cell's floor; 0 in gesture spot: where a recording's surfaces are is not known)")
      ->check(CLI::Range(0.0, 100.0));
  c->add_option("--other-arm-free", o.spot.other_arm_free,
                "pointing needs the other arm not held out as well (default true)");
  c->add_option("--confirm", o.spot.confirm,
                "s pointing must stay held after --hold before the event goes out, or it is dropped (default 0: none; spot --model: "
                "the model's)")
      ->check(CLI::Range(0.0, 10.0));
  c->add_option("--min-confidence", o.spot.min_confidence,
                "events less sure than this (1 - exp(-margin) over the next class) are dropped (default 0; spot --model: the model's)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--min-straightness", o.spot.min_straightness,
                "pointing: shoulder to hand over the arm's length, averaged over the hold, at least this (1: straight; 0: any; default 0.9)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--max-lean", o.spot.max_lean_m,
                "pointing: the neck at most this far (m) off the torso horizontally over the hold, the trunk upright (0: any; "
                "default 0.07 in gesture sim, whose world is level; 0 in gesture spot: a recording's camera may be tilted)")
      ->check(CLI::Range(0.0, 1.0));
  return max_target;
}

}  // namespace

void add_gesture_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* g = app.add_subcommand("gesture", "Gesture recognition with HMMs: train, cross-validate, classify recorded clips");
  g->require_subcommand(1);
  auto o = std::make_shared<GestureOptions>();

  auto* t = g->add_subcommand("train", "Train one HMM per class (and the rejection threshold) on labelled clips; with --spot a "
                                       "stream spotter on annotated continuous streams");
  add_common(t, *o, true);
  add_stream_options(t, *o,
                     "the inputs are annotated continuous streams (see cv --spot): train a sliding-window stream spotter "
                     "on all of them, for `gesture spot --model`; --features defaults to body here");
  t->add_option("--out", o->out, "write the classifier (JSON)");
  t->callback([o, t, &run] {
    o->best_configuration = !o->spot_streams && !any_model_option(t);
    if (o->spot_streams && t->get_option("--features")->count() == 0) o->features = "body";
    run = [o] { return gesture_train(*o); };
  });

  auto* cv = g->add_subcommand("cv", "Cross-validate: confusion matrix, accuracy, per-class precision/recall/F1, ROC");
  add_common(cv, *o, true);
  add_stream_options(cv, *o,
                     "the inputs are annotated continuous streams (an .annotations.csv beside each file, or --format msrc12's "
                     ".tagstream): leave one subject out, spot with a sliding window, score events against the annotations "
                     "(per class P/R/F1, macro F1, latency); --features defaults to body here");
  cv->add_flag("--nearest", o->nearest,
               "an experiment: each clip takes the class of its nearest training clip by dynamic time warping (the "
               "features and --hands as given; the HMM options unused); cross-validation only");
  cv->add_option("--split", o->split,
                 "lso: leave one subject out (default); kfold: stratified k-fold; size: the subjects with the shorter "
                 "arms against those with the longer (trained on one half, tested on the other, both ways)")
      ->check(CLI::IsMember({"lso", "kfold", "size"}));
  cv->add_option("--folds", o->folds, "k for --split kfold (default 5)")->check(CLI::Range(2, 1000));
  cv->add_option("--svg", o->svg, "write the confusion matrix as SVG");
  cv->add_flag("--sweep", o->sweep, "try every states x mixtures x covariance (x initialisation) combination and report the best");
  cv->add_flag("--nested", o->nested,
               "with --sweep: also choose the configuration inside each fold from its training clips alone and score it on the "
               "held-out fold (the unbiased figure for the sweep's winner; about folds x the sweep's time)")
      ->needs("--sweep");
  cv->add_option("--sweep-states", o->sweep_states, "states to try (default 3 5 7 9)")->check(CLI::Range(1, 50));
  cv->add_option("--sweep-mixtures", o->sweep_mixtures, "mixtures to try (default 1 2 3)")->check(CLI::Range(1, 20));
  cv->add_option("--sweep-covariance", o->sweep_covariance, "covariances to try (default full diag)")
      ->check(CLI::IsMember({"full", "diag"}));
  cv->add_option("--sweep-init", o->sweep_init, "initialisations to try (default: --init's)")
      ->check(CLI::IsMember({"segments", "kmeans"}));
  cv->callback([o, cv, &run] {
    // --spot's defaults are its best measured configuration (docs/experiments/2026-12-04-msrc12-spotting.md).
    o->best_configuration = !o->spot_streams && !o->sweep && !any_model_option(cv);
    if (o->spot_streams && cv->get_option("--features")->count() == 0) o->features = "body";
    run = [o] { return gesture_cv(*o); };
  });

  auto* f = g->add_subcommand("features", "Print the per-frame features of recordings as CSV (what the models see)");
  add_common(f, *o, false);
  f->add_option("--features", o->features, "feature set: thesis8 (default; the thesis's 8), extended, body, hands, arm (hands and arm need wrists: Kinect v1/v2 recordings)")
      ->check(CLI::IsMember({"body", "thesis8", "extended", "hands", "arm"}));
  f->callback([o, &run] { run = [o] { return gesture_features(*o); }; });

  auto* sp = g->add_subcommand("spot", "Spot gestures in continuous streams of recorded clips: each subject's clips one "
                                      "after another, a model trained on the other subjects; precision, recall, latency");
  add_common(sp, *o, true);
  sp->add_option("--rest", o->rest,
                 "s of rest put between clips (and before the first and after the last): the arms lowered over 0.5 s to hang "
                 "below the shoulders, held, raised over 0.5 s into the next clip (default 0: none)")
      ->check(CLI::Range(0.0, 10.0));
  sp->add_option("--gap", o->gap, "s of the last frame held between clips (default 0: the clips' own idle starts and ends are the rest)")->check(CLI::Range(0.0, 10.0));
  add_spotter_options(sp, *o);
  sp->add_option("--model", o->model,
                 "spot with a trained model in the inputs (no training): a stream spotter from `gesture train --spot` (scored "
                 "where the inputs have annotations), or a clip classifier (a file, or the built-in 'sim') run through the "
                 "live component's spotter (events listed and counted per hour)")
      ->check(CLI::ExistingFile | CLI::IsMember(builtin_model_names()));
  sp->callback([o, sp, &run] {
    o->operating_point_given[0] = sp->count("--min-confidence") > 0;
    o->operating_point_given[1] = sp->count("--confirm") > 0;
    run = [o] { return gesture_spot(*o); };
  });

  auto* sm = g->add_subcommand("sim", "Simulated pointing sessions (no outside data): train a classifier on some, spot "
                                     "gestures in the others' fused stream and score precision, recall, latency and target error");
  sm->add_flag("--json", o->json, "machine-readable output");
  add_model_options(sm, *o);
  sm->add_option("--train-sessions", o->train_sessions, "pointing sessions to train on (default 24)")->check(CLI::Range(1, 200));
  sm->add_option("--test-sessions", o->test_sessions, "sessions to spot on (default 4)")->check(CLI::Range(1, 200));
  sm->add_option("--train-heights", o->train_heights,
                 "the training sessions' people's heights, m, one session each in turn (default 1.75: the built-in model)")
      ->delimiter(',')
      ->check(CLI::Range(1.0, 2.2));
  sm->add_option("--test-height", o->test_height,
                 "the test sessions' people's height, m (training: 1.75): how the model does on people of another size")
      ->check(CLI::Range(1.0, 2.2));
  sm->add_option("--test-noise-scale", o->test_noise_scale,
                 "scale of the trackers' random errors in the test sessions (default 1; 0 leaves the skeleton convention's "
                 "offsets, the lag and the geometry: how far the targets are off without the tracker's noise)")
      ->check(CLI::Range(0.0, 10.0));
  sm->add_option("--quiet-scenarios", o->quiet_scenarios,
                 "simulator scenarios where nobody gestures, spotted for false alarms (default walk,360,hide,box,occ,sit,arms,work)")
      ->delimiter(',')
      ->check(CLI::IsMember(sim::scenario_names()));
  sm->add_option("--quiet-sessions", o->quiet_sessions, "sessions of each of them (default 1; 0: none)")->check(CLI::Range(0, 200));
  sm->add_option("--train-quiet-sessions", o->train_quiet_sessions,
                 "training sessions of each of them whose false alarms the model is trained again against (default 8; 0: none)")
      ->check(CLI::Range(0, 200));
  sm->add_option("--out", o->out, "write the trained classifier (JSON), e.g. for the gesture component");
  auto* sim_max_target = add_spotter_options(sm, *o);
  sm->add_option("--window", o->spot.window, "s over which hand speed is measured (default 0.25)")->check(CLI::Range(0.03, 2.0));
  sm->callback([o, sm, sim_max_target, &run] {
    if (sim_max_target->count() == 0) o->spot.max_target = sim_spotter_options().max_target;  // the cell's floor
    if (sm->count("--max-lean") == 0) o->spot.max_lean_m = sim_spotter_options().max_lean_m;  // its level world
    run = [o] { return gesture_sim(*o); };
  });

  auto* c = g->add_subcommand("classify", "Classify recordings with a trained classifier");
  add_common(c, *o, false);
  c->add_option("--model", o->model, "classifier file from `gesture train`")->required()->check(CLI::ExistingFile);
  c->callback([o, &run] { run = [o] { return gesture_classify(*o); }; });
}

}  // namespace skelgraph::cli
