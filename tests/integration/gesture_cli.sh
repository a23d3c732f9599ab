#!/usr/bin/env bash
# `skelgraph gesture` end to end on the real Kinder-Gator recordings
# (../shared/data, read in place): train, classify with --json, k-fold
# cross-validation with an SVG confusion matrix, a small --sweep, the features
# as CSV, and bad input (a class file with an error, a malformed model).
source "$(dirname "$0")/lib.sh"
S=$SKELGRAPH
KG=${SKELGRAPH_DATA_DIR:-$SKELGRAPH_SOURCE_DIR/../shared/data}/kinder-gator/adults
[ -d "$KG" ] || fail "$KG is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)"

# Train on 9 subjects, classify the tenth's pointing and stop clips.
mkdir -p "$WORK/train"
for f in "$KG"/*.csv; do case "$f" in *p976_*) ;; *) ln -s "$f" "$WORK/train/";; esac; done
"$S" gesture train "$WORK/train" --states 5 --out "$WORK/model.json" --json >"$WORK/train.json" 2>"$WORK/train.err" \
  || fail "gesture train: $(cat "$WORK/train.err")"
json_check "$WORK/train.json" 'd["clips"] == 144 and d["labels"] == ["point", "other"] and d["config"]["features"] == "thesis8"'
"$S" gesture classify --model "$WORK/model.json" --json "$KG"/*p976_*Point* "$KG"/*p976_*Walk* >"$WORK/classify.json" \
  || fail "gesture classify"
json_check "$WORK/classify.json" 'len(d) == 2 and d[0]["label"] == "point" and d[1]["best"] == "other" and d[0]["scores"]["point"] > d[0]["scores"]["other"]'
ok "train on 9 subjects, the tenth's pointing clip is pointing and walking is not"

# The same with the hands features (wrists from the Kinect v1 files): "signal to stop" is not pointing.
"$S" gesture train "$WORK/train" --features hands --states 3 --mixtures 2 --covariance diag --out "$WORK/hands.json" --json \
  >"$WORK/train_hands.json" 2>"$WORK/train.err" || fail "gesture train --features hands: $(cat "$WORK/train.err")"
json_check "$WORK/train_hands.json" 'd["config"]["features"] == "hands"'
"$S" gesture classify --model "$WORK/hands.json" --json "$KG"/*p976_*Point* "$KG"/*p976_*stop* >"$WORK/classify_hands.json" \
  || fail "gesture classify (hands)"
json_check "$WORK/classify_hands.json" 'len(d) == 2 and d[0]["label"] == "point" and d[1]["best"] == "other"'
"$S" gesture features --features hands "$KG"/*p565_24-Point* >"$WORK/hands.csv" || fail "gesture features --features hands"
head -1 "$WORK/hands.csv" | grep -q "right_hand_length" || fail "hands features header: $(head -1 "$WORK/hands.csv")"
ok "hands features: train, classify pointing and signal-to-stop apart"
# The live component refuses such a model: the skeleton topics carry no wrists.
set +e
timeout 20 "$S" run gesture -p model="$WORK/hands.json" >"$WORK/run_hands.out" 2>"$WORK/run_hands.err"
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "run gesture with a hands model exited $rc, expected 1 (a component that cannot start): $(cat "$WORK/run_hands.err")"
grep -q "need wrist joints" "$WORK/run_hands.err" || fail "run gesture with a hands model: $(cat "$WORK/run_hands.err")"
ok "the gesture component refuses a hands model: $(grep -m1 'wrist' "$WORK/run_hands.err")"

# With no model option, train takes the class set's best measured configuration (wrists here: hands 3/2/diag) and says so.
"$S" gesture train "$WORK/train" --json >"$WORK/train_default.json" 2>"$WORK/train_default.err" \
  || fail "gesture train with defaults: $(cat "$WORK/train_default.err")"
json_check "$WORK/train_default.json" 'd["clips"] == 144 and d["config"]["features"] == "hands" and d["config"]["states"] == 3 and d["config"]["mixtures"] == 2 and d["config"]["covariance"] == "diag"'
grep -q "the best measured for these classes (two-class 98.8 %" "$WORK/train_default.err" || fail "train's defaults unannounced: $(cat "$WORK/train_default.err")"
grep -q "for a live model give --features thesis8" "$WORK/train_default.err" || fail "train's defaults: no word on the live component: $(cat "$WORK/train_default.err")"
ok "train with no model option: $(grep -m1 '^model:' "$WORK/train_default.err" | cut -c1-90)"

# Five classes, stratified 2-fold, on the labelled clips only.
mkdir -p "$WORK/five"
for a in Point-at-the-camera Push-an-imaginary-button Walk-in-place Raise-your-hand- Wave-your-hand-; do ln -s "$KG"/*"$a"* "$WORK/five/"; done
"$S" gesture cv "$WORK/five" --classes five-class --split kfold --folds 2 --states 3 --svg "$WORK/cm.svg" --json >"$WORK/cv.json" 2>"$WORK/cv.err" \
  || fail "gesture cv: $(cat "$WORK/cv.err")"
json_check "$WORK/cv.json" 'sum(map(sum, d["metrics"]["confusion"])) == 50 and d["metrics"]["accuracy"] > 0.4 and len(d["clips"]) == 50 and d["folds"] == 2'
grep -q "<svg" "$WORK/cm.svg" || fail "no SVG confusion matrix"
ok "five-class 2-fold cross-validation: confusion matrix over 50 clips, SVG written"
# The five-class set-up of the README: active-arm features, k-means initialisation, best of several restarts.
"$S" gesture cv "$WORK/five" --classes five-class --split kfold --folds 2 --features arm --states 3 --covariance diag \
  --init kmeans --restarts 4 --json >"$WORK/cv_km.json" 2>"$WORK/cv.err" || fail "gesture cv --init kmeans: $(cat "$WORK/cv.err")"
json_check "$WORK/cv_km.json" 'd["config"]["init"] == "kmeans" and d["config"]["restarts"] == 4 and sum(map(sum, d["metrics"]["confusion"])) == 50 and d["metrics"]["accuracy"] > 0.4'
"$S" gesture cv "$WORK/five" --classes five-class --split kfold --folds 2 --json >"$WORK/cv_default.json" 2>"$WORK/cv.err" \
  || fail "gesture cv five-class with defaults: $(cat "$WORK/cv.err")"
json_check "$WORK/cv_default.json" 'd["config"]["features"] == "arm" and d["config"]["init"] == "kmeans" and d["config"]["restarts"] == 16 and d["config"]["covariance"] == "diag" and sum(map(sum, d["metrics"]["confusion"])) == 50'
"$S" gesture cv "$WORK/five" --classes five-class --init random 2>"$WORK/bad.err" && fail "--init random was accepted"
grep -q "init" "$WORK/bad.err" || fail "--init random: $(cat "$WORK/bad.err")"
ok "five-class with k-means initialisation and restarts (the default with no model option); an unknown --init is refused"

# A small sweep (2 states x 2 covariances, 1 mixture; under a second): every configuration is reported, and the
# winner (config and metrics) is the sweep's best by accuracy, then the first class's F1.
"$S" gesture cv "$WORK/five" --classes five-class --split kfold --folds 2 --sweep --sweep-states 2 3 --sweep-mixtures 1 \
  --sweep-covariance diag full --json >"$WORK/sweep.json" 2>"$WORK/sweep.err" || fail "gesture cv --sweep: $(tail -3 "$WORK/sweep.err")"
python3 - "$WORK/sweep.json" <<'PY' || fail "gesture cv --sweep: $(cat "$WORK/sweep.json")"
import json, sys
d = json.load(open(sys.argv[1]))
first = d["metrics"]["labels"][0]
f1 = "f1_" + first
runs = d["sweep"]
tried = sorted((r["states"], r["mixtures"], r["covariance"]) for r in runs)
assert tried == [(2, 1, "diag"), (2, 1, "full"), (3, 1, "diag"), (3, 1, "full")], tried
assert all(r["init"] == "segments" and r["features"] == "thesis8" for r in runs), runs
win = [r for r in runs if {k: v for k, v in r.items() if k not in ("accuracy", f1, "detection_auc")} == d["config"]]
assert len(win) == 1, (d["config"], runs)
win = win[0]
assert win["accuracy"] == d["metrics"]["accuracy"] and win[f1] == d["metrics"]["per_class"][first]["f1"], (win, d["metrics"])
key = lambda r: (r["accuracy"], r[f1], r["detection_auc"] if r["detection_auc"] is not None else float("-inf"))
assert key(win) == max(map(key, runs)), (win, runs)
assert len({key(r) for r in runs}) > 1, runs  # the configurations do differ, so the choice is not vacuous
assert sum(map(sum, d["metrics"]["confusion"])) == 50, d["metrics"]["confusion"]
PY
ok "sweep over 4 configurations: all reported, the winner ($(json_get "$WORK/sweep.json" 'd["config"]["states"]') states, $(json_get "$WORK/sweep.json" 'd["config"]["covariance"]'), accuracy $(json_get "$WORK/sweep.json" 'd["metrics"]["accuracy"]')) is the best"

"$S" gesture features "$KG"/*p565_24-Point* >"$WORK/features.csv" || fail "gesture features"
head -1 "$WORK/features.csv" | grep -q "right_forearm_angle_speed" || fail "features header: $(head -1 "$WORK/features.csv")"
[ "$(wc -l <"$WORK/features.csv")" -gt 100 ] || fail "features: too few rows"
ok "features as CSV"

printf 'classes:\n  point: [Point-at-the-camera]\n  stop: [Point-at-the-camera]\n' >"$WORK/bad.yaml"
"$S" gesture cv "$WORK/five" --classes "$WORK/bad.yaml" 2>"$WORK/bad.err" && fail "a class file with an action in two classes was accepted"
grep -q "bad.yaml:3" "$WORK/bad.err" || fail "the class-file error does not name the line: $(cat "$WORK/bad.err")"
echo '{"format": "skelgraph-gesture-classifier", "version": 1}' >"$WORK/bad.json"
"$S" gesture classify --model "$WORK/bad.json" "$KG"/*p565_24-Point* 2>"$WORK/bad.err" && fail "a malformed model was accepted"
grep -q "missing field" "$WORK/bad.err" || fail "malformed model error: $(cat "$WORK/bad.err")"
ok "bad class file and malformed model: clear errors"

# Bad files in a batch: each reported with file:line, the others still processed, exit 2 at the end.
mkdir -p "$WORK/batch"
point=$(ls "$KG"/*p976_*Point* | head -1)
ln -s "$point" "$WORK/batch/a_point.csv"
head -1 "$point" >"$WORK/batch/b_header_only.csv"
{ head -1 "$point"; printf '12\x1b[2J,3\n'; } >"$WORK/batch/c_control_bytes.csv"
{ head -1 "$point"; sed -n 2,4p "$point" | sed 's/^[^,]*,/x\x07y,/'; sed -n '5,$p' "$point"; } >"$WORK/batch/d_bad_lines.csv"
rc=0
"$S" gesture classify --model "$WORK/model.json" --json "$WORK/batch" >"$WORK/batch.json" 2>"$WORK/batch.err" || rc=$?
[ "$rc" -eq 2 ] || fail "classify a batch with bad files exited $rc, expected 2: $(cat "$WORK/batch.err")"
json_check "$WORK/batch.json" 'len(d) == 4 and d[0]["label"] == "point" and all("error" in e for e in d[1:]) and "label" not in d[1]'
grep -q "b_header_only.csv:1: no data rows" "$WORK/batch.err" || fail "a header-only clip: $(cat "$WORK/batch.err")"
grep -q "c_control_bytes.csv:2: expected 63 fields" "$WORK/batch.err" || fail "a short line: $(cat "$WORK/batch.err")"
grep -q "d_bad_lines.csv:2: column 'Timestamp' expects a number, got 'x.x07y'" "$WORK/batch.err" || fail "a bad number: $(cat "$WORK/batch.err")"
grep -q "3 of 4 inputs were bad" "$WORK/batch.err" || fail "no summary of the bad inputs: $(cat "$WORK/batch.err")"
LC_ALL=C grep -q $'[\x01-\x08\x0b-\x1f\x7f]' "$WORK/batch.err" "$WORK/batch.json" && fail "raw control bytes printed: $(cat -v "$WORK/batch.err")"
# --on-error skip: the file with bad lines is read without them (and says so); the header-only clip stays bad.
rc=0
"$S" gesture classify --model "$WORK/model.json" --json --on-error skip "$WORK/batch/d_bad_lines.csv" "$WORK/batch/b_header_only.csv" \
  >"$WORK/skip.json" 2>"$WORK/skip.err" || rc=$?
[ "$rc" -eq 2 ] || fail "classify --on-error skip exited $rc, expected 2 (a header-only clip): $(cat "$WORK/skip.err")"
json_check "$WORK/skip.json" 'len(d) == 2 and d[0]["label"] == "point" and "error" in d[1]'
grep -q "d_bad_lines.csv: 3 bad lines of .* skipped" "$WORK/skip.err" || fail "skipped lines not reported: $(cat "$WORK/skip.err")"
# Training goes on without the bad files (exit 2), and with --on-error skip uses the file with bad lines.
mkdir -p "$WORK/train_bad" && cp -s "$WORK/train"/*.csv "$WORK/train_bad/" && cp "$WORK/batch/b_header_only.csv" "$WORK/train_bad/"
rc=0
"$S" gesture train "$WORK/train_bad" --states 3 --json >"$WORK/train_bad.json" 2>"$WORK/train_bad.err" || rc=$?
[ "$rc" -eq 2 ] || fail "train with a bad file exited $rc, expected 2: $(cat "$WORK/train_bad.err")"
json_check "$WORK/train_bad.json" 'd["clips"] == 144'
grep -q "b_header_only.csv:1" "$WORK/train_bad.err" || fail "train: the bad file is not named: $(cat "$WORK/train_bad.err")"
# play-data --info: the same rule.
rc=0
"$S" play-data kinder-gator --info "$point" "$WORK/batch/b_header_only.csv" >"$WORK/info.json" 2>"$WORK/info.err" || rc=$?
[ "$rc" -eq 2 ] || fail "play-data --info with a bad file exited $rc, expected 2"
json_check "$WORK/info.json" 'len(d) == 2 and d[0]["frames"] > 10 and "no data rows" in d[1]["error"]'
ok "bad files in a batch: named with file:line, control bytes escaped, the others processed, exit 2"

# Continuous streams: three subjects, each spotted by a model trained on the other two.
mkdir -p "$WORK/three"
for f in "$KG"/*p565_* "$KG"/*p604_* "$KG"/*p734_*; do ln -s "$f" "$WORK/three/"; done
"$S" gesture spot "$WORK/three" --states 5 --json >"$WORK/spot.json" 2>"$WORK/spot.err" || fail "gesture spot: $(cat "$WORK/spot.err")"
json_check "$WORK/spot.json" 'd["spotting"]["truth"] == 3 and len(d["subjects"]) == 3 and d["spotting"]["events"] == d["spotting"]["true_positive"] + d["spotting"]["false_positive"]'
ok "spotting in continuous streams of real clips, leave-subject-out"

# The same with an arms-down rest put between the clips; the stream is longer by the rests.
"$S" gesture spot "$WORK/three" --states 5 --rest 1 --json >"$WORK/spot_rest.json" 2>"$WORK/spot.err" || fail "gesture spot --rest: $(cat "$WORK/spot.err")"
json_check "$WORK/spot_rest.json" 'd["rest_s"] == 1 and d["spotting"]["truth"] == 3 and len(d["subjects"]) == 3'
# Each event says which clip it came in; each subject lists its 16 clips in stream order, motion inside the clip.
json_check "$WORK/spot_rest.json" 'sum(len(s["spotted"]) for s in d["subjects"]) == d["spotting"]["events"] and all(len(s["clips_in_stream"]) == s["clips"] == 16 and all(c["clip_start_s"] <= c["motion_start_s"] <= c["motion_end_s"] <= c["clip_end_s"] for c in s["clips_in_stream"]) and all(a["clip_end_s"] < b["clip_start_s"] for a, b in zip(s["clips_in_stream"], s["clips_in_stream"][1:])) and sum(c["label"] == "point" for c in s["clips_in_stream"]) == 1 for s in d["subjects"]) and all(e["clip"] in [c["clip"] for c in s["clips_in_stream"]] + ["rest"] for s in d["subjects"] for e in s["spotted"])'
ok "spotting with rests between the clips"

# Annotated continuous streams (MSRC-12, action points in .tagstream files):
# leave-subject-out spotting with the sliding-window spotter, scored per class.
MS=${SKELGRAPH_DATA_DIR:-$SKELGRAPH_SOURCE_DIR/../shared/data}/msrc12
[ -d "$MS" ] || fail "$MS is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)"
mkdir -p "$WORK/msrc"
for f in "$MS"/P1_1_1_p*.* "$MS"/P1_1_12_p*.*; do ln -s "$f" "$WORK/msrc/"; done
"$S" gesture cv --spot --format msrc12 "$WORK/msrc" --json >"$WORK/msrc.json" 2>"$WORK/msrc.err" || fail "cv --spot: $(cat "$WORK/msrc.err")"
json_check "$WORK/msrc.json" 'd["streams"] == 6 and d["subjects"] == ["p06", "p19", "p21"] and [c["label"] for c in d["per_class"]] == ["G1  lift outstretched arms", "G12 Kick"] and [c["truth"] for c in d["per_class"]] == [30, 30] and d["config"]["features"] == "body" and d["spotting"]["model"] == "knn" and d["macro_f1"] > 0.6'
# The data set's file without a single skeleton is bad input: named, the others still scored, exit 2.
ln -s "$MS"/P1_1_12A_p19.csv "$MS"/P1_1_12A_p19.tagstream "$WORK/msrc/"
rc=0
"$S" gesture cv --spot --format msrc12 "$WORK/msrc" --json >"$WORK/msrc2.json" 2>"$WORK/msrc2.err" || rc=$?
[ "$rc" -eq 2 ] || fail "cv --spot with an empty stream exited $rc, expected 2"
grep -q "P1_1_12A_p19.csv:1029: no skeleton frames" "$WORK/msrc2.err" || fail "the empty stream: $(cat "$WORK/msrc2.err")"
json_check "$WORK/msrc2.json" 'd["streams"] == 6'
ok "annotated streams (MSRC-12 G1, G12): leave-subject-out spotting, macro F1 $(json_get "$WORK/msrc.json" 'round(d["macro_f1"], 3)')"

# A stream spotter trained on two people's annotated streams, saved, then used
# on the third person's (gesture spot --model): events per file, scored.
mkdir -p "$WORK/msrc_train"
for f in "$MS"/P1_1_1_p06.* "$MS"/P1_1_1_p19.* "$MS"/P1_1_12_p06.* "$MS"/P1_1_12_p19.*; do ln -s "$f" "$WORK/msrc_train/"; done
"$S" gesture train --spot --format msrc12 "$WORK/msrc_train" --out "$WORK/stream_model.json" --json >"$WORK/stream_train.json" \
  2>"$WORK/stream_train.err" || fail "train --spot: $(cat "$WORK/stream_train.err")"
json_check "$WORK/stream_train.json" 'd["streams"] == 4 and len(d["classes"]) == 2 and d["training_windows"] > 300'
"$S" gesture spot --model "$WORK/stream_model.json" --format msrc12 "$MS"/P1_1_1_p21.csv "$MS"/P1_1_12_p21.csv --json \
  >"$WORK/stream_spot.json" 2>"$WORK/stream_spot.err" || fail "spot --model: $(cat "$WORK/stream_spot.err")"
json_check "$WORK/stream_spot.json" 'len(d["files"]) == 2 and all(len(f["events"]) > 3 for f in d["files"]) and [c["truth"] for c in d["per_class"]] == [11, 11] and d["macro_f1"] > 0.7'
# A clip classifier (not a stream spotter) runs through the live spotter instead.
"$S" gesture spot --model "$WORK/model.json" --format msrc12 "$MS"/P1_1_1_p21.csv --json >"$WORK/clip_model.json" \
  2>"$WORK/clip_model.err" || fail "a clip classifier given to spot --model: $(cat "$WORK/clip_model.err")"
json_check "$WORK/clip_model.json" 'len(d["files"]) == 1 and "events_per_hour" in d'
# Ctrl-C stops offline work at once (exit 130), with nothing half-printed on stdout.
"$S" gesture sim --test-sessions 30 --json >"$WORK/int.json" 2>"$WORK/int.err" &
sim_pid=$!
wait_for_match "$WORK/int.err" "simulating" 60 || fail "gesture sim shows no progress: $(cat "$WORK/int.err")"
kill -INT "$sim_pid"
rc=0
wait "$sim_pid" || rc=$?
[ "$rc" = 130 ] || fail "gesture sim after SIGINT: exit $rc, expected 130: $(tail -2 "$WORK/int.err")"
[ ! -s "$WORK/int.json" ] || fail "an interrupted gesture sim printed: $(head -c 300 "$WORK/int.json")"
grep -q "interrupted (SIGINT)" "$WORK/int.err" || fail "no word of the interruption: $(tail -2 "$WORK/int.err")"
ok "Ctrl-C ends offline work at once: exit 130, nothing on stdout"
# The operating point travels with a model: written by gesture sim --out, used by spot unless given.
"$S" gesture sim --train-sessions 4 --train-quiet-sessions 1 --test-sessions 1 --quiet-sessions 1 --min-confidence 0.3 \
  --confirm 0.25 --out "$WORK/op.json" --json >"$WORK/op_sim.json" 2>"$WORK/op_sim.err" || fail "sim --out: $(cat "$WORK/op_sim.err")"
json_check "$WORK/op_sim.json" 'd["operating_point"]["min_confidence"] == 0.3 and d["operating_point"]["confirm_s"] == 0.25 and 0 <= d["operating_point"]["recall"] <= 1'
"$S" gesture spot --model "$WORK/op.json" --format msrc12 "$MS"/P1_1_1_p21.csv --json >"$WORK/op_spot.json" 2>/dev/null || fail "spot with op.json"
json_check "$WORK/op_spot.json" 'd["operating_point"] == {"min_confidence": 0.3, "confirm_s": 0.25}'
"$S" gesture spot --model "$WORK/op.json" --min-confidence 0 --format msrc12 "$MS"/P1_1_1_p21.csv --json >"$WORK/op_spot0.json" 2>/dev/null ||
  fail "spot --min-confidence 0"
json_check "$WORK/op_spot0.json" 'd["operating_point"] == {"min_confidence": 0, "confirm_s": 0.25}'
ok "stream spotter trained on two people, spotting the third's streams: macro F1 $(json_get "$WORK/stream_spot.json" 'round(d["macro_f1"], 3)')"

# A clip classifier through the live spotter over recordings where nobody
# points (MSRC-12's gestures): events listed per file and counted per hour.
"$S" gesture spot --model sim --format msrc12 "$MS"/P1_1_10_p06.csv "$MS"/P1_1_12_p19.csv --json >"$WORK/quiet.json" \
  2>"$WORK/quiet.err" || fail "spot --model sim: $(cat "$WORK/quiet.err")"
json_check "$WORK/quiet.json" 'len(d["files"]) == 2 and d["seconds"] > 100 and all(f["span_s"] > 20 for f in d["files"]) and sum(len(f["events"]) for f in d["files"]) == round(sum(d["events_per_hour"].values()) * d["seconds"] / 3600)'
rc=0
"$S" gesture spot --model nosuch --format msrc12 "$MS"/P1_1_10_p06.csv >/dev/null 2>"$WORK/nosuch.err" || rc=$?
[ "$rc" -eq 2 ] || fail "an unknown model was taken: exit $rc"
ok "the built-in pointing model over MSRC-12 streams: $(json_get "$WORK/quiet.json" 'd["events_per_hour"]') events per hour"
