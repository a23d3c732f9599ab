#!/usr/bin/env bash
# Real recordings from ../shared/data replayed as live streams, seen by the topic tools.
source "$(dirname "$0")/lib.sh"
DATA="$SRC/../shared/data"
[ -d "$DATA" ] || fail "$DATA is missing: the tests read the shared data sets beside the repository"

# KinectMultiTrack: two sensors, one file, at the recorded rate.
mt="$DATA/kinect-multitrack/Experiments_1_2_3_6/Study_1_Kinect_2_Time_12_07_07_PM.csv"
"$SKELGRAPH" play-data multitrack "$mt" --loop --duration 8 2>"$WORK/play.err" &
play=$!
"$SKELGRAPH" topic echo skelgraph/skeleton/raw --count 40 --json --timeout 10 >"$WORK/raw.jsonl"
python3 - "$WORK/raw.jsonl" <<'PY' || fail "raw skeletons wrong: $(head -c 600 "$WORK/raw.jsonl")"
import json, sys
rows = [json.loads(l)["data"] for l in open(sys.argv[1])]
sensors = {r["sensor_id"] for r in rows}
assert sensors == {"kinect_138_251_207_136", "kinect_138_251_213_82"}, sensors
for r in rows:
    j = {x["name"]: x for x in r["joints"]}
    assert len(r["joints"]) == 15
    assert j["head"]["position"]["y"] > j["torso"]["position"]["y"], r   # y up
    assert 0.5 < j["torso"]["position"]["z"] < 5.0, r                   # metres from the sensor
PY
ok "multitrack replay: two sensor ids, canonical joints in metres, y up"
"$SKELGRAPH" topic hz skelgraph/skeleton/raw --window 2 --json >"$WORK/hz.json"
# Both sensors' frames flow through a 2 s window (at the recording's ~29 Hz each: about
# 116; how fast on a busy machine is the benchmarks' business), and topic hz agrees with itself.
json_check "$WORK/hz.json" 'd["samples"] >= 40 and d["min_period_s"] <= 1 / d["rate_hz"] <= d["max_period_s"]'
ok "multitrack replay: $(json_get "$WORK/hz.json" 'd["samples"]') skeletons in 2 s ($(json_get "$WORK/hz.json" 'round(d["rate_hz"], 1)') Hz)"
wait "$play" || fail "play-data failed: $(cat "$WORK/play.err")"

# Bad input: a clear message naming file:line, exit 2, nothing published.
printf 'Timestamp,oops\n' >"$WORK/bad.csv"
set +e
"$SKELGRAPH" play-data kinder-gator "$WORK/bad.csv" --info >/dev/null 2>"$WORK/bad.err"
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "bad file: exit $rc, expected 2"
grep -q "bad.csv:1: expected 63 fields" "$WORK/bad.err" || fail "bad file message: $(cat "$WORK/bad.err")"
ok "bad file -> exit 2: $(cat "$WORK/bad.err")"
echo "playback: all checks passed"
