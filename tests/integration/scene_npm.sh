#!/usr/bin/env bash
# Scene recordings as Foxglove/Lichtblick's 3-D panel reads them
# (tests/npm/check_scene.mjs: the schemas are @foxglove/schemas' own, every
# message decodes and re-encodes, every skeleton entity matches its source
# skeleton, every frame resolves to `cell`), for:
# 1. the demo's live session (raw, fused, truth, the sensors' poses): its
#    recorder writes the scene into the recording as samples arrive;
# 2. one file of every wire type (tests/support/write_mcap_samples): pointing
#    and the robot's capsules become entities;
# 3. real data sets imported (Kinder-Gator, KinectMultiTrack, MSRC-12) and exported
#    with the scene.
# Usage: scene_npm.sh SKELGRAPH NPM_DIR WRITE_MCAP_SAMPLES   (in a loopback-only namespace)
source "$(dirname "$0")/lib.sh"
S=$SKELGRAPH
NPM_DIR=${2:?usage: scene_npm.sh SKELGRAPH NPM_DIR WRITE_MCAP_SAMPLES}
SAMPLES=${3:?}
WRITE_IDL=$SKELGRAPH_SOURCE_DIR/components/scene/schemas/write_idl.cjs
DATA=${SKELGRAPH_DATA_DIR:-$SKELGRAPH_SOURCE_DIR/../shared/data}
check() {  # check SCENE.mcap OUT.json [live]
  node "$NPM_DIR/check_scene.mjs" "$1" "$WRITE_IDL" ${3:-} >"$2" 2>"$2.err" || fail "check_scene $1: $(cat "$2.err")"
}

# 1. The demo (short): its recording has the scene, written live by its recorder.
"$S" demo --duration 6 --report "$WORK/demo" >"$WORK/demo.out" 2>"$WORK/demo.err" || fail "demo: $(tail -5 "$WORK/demo.err")"
rec=$(ls "$WORK"/demo/recording/*.mcap | head -1)
[ -f "$rec" ] || fail "the demo recorded nothing: $(ls -R "$WORK/demo")"
check "$rec" "$WORK/demo_scene.json" live
json_check "$WORK/demo_scene.json" 'd["byKind"]["raw"] > 50 and d["byKind"]["fused"] > 50 and d["byKind"]["truth"] > 50 and d["byKind"]["sensor"] >= 2 and d["frames"] == ["sensor1", "sensor2", "world"] and d["skeletonEntities"] > 150'
ok "the demo's scene: $(cat "$WORK/demo_scene.json")"

# 2. Every wire type: pointing and the robot.
"$SAMPLES" "$WORK/samples.mcap" "$WORK/samples.jsonl" zstd
"$S" bag export --scene "$WORK/samples.mcap" --out "$WORK/samples_scene.mcap" --json >"$WORK/samples_export.json" \
  || fail "bag export --scene of the samples"
json_check "$WORK/samples_export.json" 'd["pointing"] == 1 and d["robot_states"] == 1 and d["safety"] == 1 and d["undecodable"] == 0 and d["copied"] > 10'
check "$WORK/samples_scene.mcap" "$WORK/samples_scene.json"
json_check "$WORK/samples_scene.json" 'd["byKind"]["pointing"] == 1 and d["byKind"]["robot"] == 1 and d["byKind"]["safety"] == 1 and d["byKind"]["raw"] >= 1'
ok "pointing, the robot and its safety verdict as entities: $(cat "$WORK/samples_scene.json")"

# 3. Real data sets, imported and exported with the scene.
kg=$(ls "$DATA"/kinder-gator/adults/*Point-at-the-camera*.csv | head -1)
kmt="$DATA/kinect-multitrack/Experiments_1_2_3_6/Study_12_Kinect_2_Time_5_01_13_PM.csv"
msrc="$DATA/msrc12/P1_1_11_p21.csv"
[ -f "$kg" ] && [ -f "$kmt" ] && [ -f "$msrc" ] || fail "$DATA is missing data sets: tests read ../shared/data (or SKELGRAPH_DATA_DIR)"
for set in kinder-gator:"$kg" multitrack:"$kmt" msrc12:"$msrc"; do
  format=${set%%:*} file=${set#*:}
  "$S" bag import "$format" "$file" --out "$WORK/$format.mcap" >/dev/null 2>&1 || fail "bag import $format $file"
  "$S" bag export --scene "$WORK/$format.mcap" --out "$WORK/${format}_scene.mcap" --json >"$WORK/${format}_export.json" \
    || fail "bag export --scene $format"
  check "$WORK/${format}_scene.mcap" "$WORK/${format}_scene.json"
  json_check "$WORK/${format}_scene.json" 'd["byKind"]["raw"] > 30 and d["skeletonEntities"] == d["byKind"]["raw"]'
  ok "$format: $(cat "$WORK/${format}_scene.json")"
done
