#!/usr/bin/env bash
# Depth image files as a depth source: the 12 real Kinect images of
# ../shared/data/skeltrack-depth read and summarised (skelgraph depth info),
# played on skelgraph/depth (every frame, in order, with its size), driven as a
# player (paused, stepped, sought), and bad input refused with its file named.
source "$(dirname "$0")/lib.sh"
S=$SKELGRAPH
SK=${SKELGRAPH_DATA_DIR:-$SKELGRAPH_SOURCE_DIR/../shared/data}/skeltrack-depth
[ -d "$SK" ] || fail "$SK is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)"

"$S" depth info "$SK" --width 640 --height 480 --json >"$WORK/info.json" 2>"$WORK/info.err" || fail "depth info: $(cat "$WORK/info.err")"
json_check "$WORK/info.json" 'd["images"] == d["read"] == 12 and all(f["width"] == 640 and f["height"] == 480 and f["min_mm"] >= 723 and f["max_mm"] <= 1992 and f["valid_share"] > 0.1 for f in d["files"])'
ok "12 real depth images read: $(json_get "$WORK/info.json" 'min(f["min_mm"] for f in d["files"])')-$(json_get "$WORK/info.json" 'max(f["max_mm"] for f in d["files"])') mm"

# Played: every image once, in name order, 640 x 480, with the images' readings.
"$S" topic echo skelgraph/depth --count 12 --json --timeout 30 >"$WORK/echo.jsonl" 2>"$WORK/echo.err" &
echo_pid=$!
"$S" depth play "$SK" --width 640 --height 480 --rate 15 --json >"$WORK/play.json" 2>"$WORK/play.err" || fail "depth play: $(cat "$WORK/play.err")"
wait "$echo_pid" || fail "echo: $(cat "$WORK/echo.err")"
json_check "$WORK/play.json" 'd["components"][0]["details"]["published"] == 12'
python3 - "$WORK/echo.jsonl" "$WORK/info.json" <<'PY' || fail "played frames: $(cut -c1-300 "$WORK/echo.jsonl")"
import json, sys
frames = [json.loads(l)["data"] for l in open(sys.argv[1]) if l.strip()]
info = json.load(open(sys.argv[2]))
assert [f["frame_number"] for f in frames] == list(range(12)), [f["frame_number"] for f in frames]
assert all(f["width"] == 640 and f["height"] == 480 and f["sensor_id"] == "depth1" for f in frames)
assert [f["depth_mm_valid"] for f in frames] == [f["valid_pixels"] for f in info["files"]]
PY
ok "played: 12 frames in order, the readings of each file"

# A player: paused, 3 steps, a seek to 0.5 s (frame 7 at 15 Hz... the last at or before), resumed.
"$S" depth play "$SK" --width 640 --height 480 --rate 15 --paused --json >"$WORK/step.json" 2>"$WORK/step.err" &
player=$!
"$S" player state --json --timeout 10 >"$WORK/st0.json" || fail "player state: $(cat "$WORK/step.err")"
json_check "$WORK/st0.json" 'd[0]["paused"] and d[0]["frames"] == 0 and d[0]["frame_count"] == 12'
"$S" topic echo skelgraph/depth --count 3 --json --timeout 15 >"$WORK/steps.jsonl" 2>"$WORK/steps.err" &
echo_pid=$!
wait_for_match "$WORK/steps.err" "echo: matched" 10 || fail "the echo found no depth writer: $(cat "$WORK/steps.err")"
"$S" player step --frames 3 --json >"$WORK/st1.json" || fail "step"
json_check "$WORK/st1.json" 'd[0]["paused"] and d[0]["frames"] == 3'
wait "$echo_pid" || fail "echo of the steps: $(cat "$WORK/steps.err")"
python3 -c 'import json, sys; n = [json.loads(l)["data"]["frame_number"] for l in open(sys.argv[1])]; sys.exit(n != [0, 1, 2])' \
  "$WORK/steps.jsonl" || fail "stepped frames: $(cut -c1-200 "$WORK/steps.jsonl")"
"$S" player seek 0.5 --json >"$WORK/st2.json" || fail "seek"
json_check "$WORK/st2.json" 'd[0]["paused"] and abs(d[0]["position_s"] - 7 / 15) < 1e-6'
"$S" player resume >/dev/null
wait "$player" || fail "player: $(cat "$WORK/step.err")"
json_check "$WORK/step.json" 'd["components"][0]["details"]["published"] == 3 + 5'
ok "paused, stepped frames 0-1-2, sought to 0.5 s (frame 7), played the 5 after it"

# Bad input: named, exit 2.
rc=0
"$S" depth info "$SK" >/dev/null 2>"$WORK/bad1.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q "needs the image size" "$WORK/bad1.err" || fail "raw without a size: rc $rc, $(cat "$WORK/bad1.err")"
mkdir -p "$WORK/mixed"
cp "$SK"/depth-data-82823944 "$WORK/mixed/a.raw"
head -c 1000 "$SK"/depth-data-82823944 >"$WORK/mixed/b.raw"
rc=0
"$S" depth info "$WORK/mixed" --width 640 --height 480 --json >"$WORK/mixed.json" 2>"$WORK/bad2.err" || rc=$?
[ "$rc" -eq 2 ] || fail "a truncated image: exit $rc, expected 2"
grep -q "b.raw: 1000 bytes; a raw 640 x 480 uint16 image has 614400" "$WORK/bad2.err" || fail "truncated: $(cat "$WORK/bad2.err")"
json_check "$WORK/mixed.json" 'd["read"] == 1 and "error" in d["files"][1]'
rc=0
"$S" depth play "$WORK/mixed" --width 640 --height 480 --duration 30 >"$WORK/bad3.out" 2>"$WORK/bad3.err" || rc=$?
[ "$rc" -ne 0 ] || fail "played a folder whose second image is truncated"
grep -q "b.raw: 1000 bytes; a raw 640 x 480 uint16 image has 614400" "$WORK/bad3.out" "$WORK/bad3.err" \
  || fail "the truncated image is not named: $(cat "$WORK/bad3.out" "$WORK/bad3.err")"
grep -q "published\|1 published" "$WORK/bad3.out" && fail "frames went out before the bad file was found: $(cat "$WORK/bad3.out")"
ok "bad input named: a raw image without a size, a truncated one"

# The tracker on the real images (issue 35): close views from the waist up, no floor in sight, cut off below.
"$S" depth track "$SK" --width 640 --height 480 --each-alone --json >"$WORK/track.json" 2>"$WORK/track.err" ||
  fail "depth track: $(tail -3 "$WORK/track.err")"
python3 - "$WORK/track.json" <<'PY' || fail "the tracker on skeltrack-depth (above)"
import json, sys
d = json.load(open(sys.argv[1]))
problems = []
if d["with_a_person"] != 12: problems.append(f'{d["with_a_person"]} of 12 images with a person')
# The nearest person's reported joints on the person (measured 2026-12-06: 127 of 132; 115 of 131 before
# hands held out, bent arms and free space), at most two off in any image; the legs, below the image, not reported.
share = d["nearest_joints_on_person"] / max(1, d["nearest_joints_reported"])
if share < 0.95: problems.append(f"only {share:.0%} of the joints on the person")
for f in d["files"]:
    for s in f["skeletons"]:
        off = [n for n, j in s["joints"].items() if not j["on_person"]]
        if s["nearest"] and len(off) > 2: problems.append(f'{f["file"]}: {len(off)} joints off the person: {off}')
for f in d["files"]:
    for s in f["skeletons"]:
        if s["nearest"] and any(j in s["joints"] for j in ("left_foot", "right_foot")):
            problems.append(f'{f["file"]}: a foot reported in a view cut off at the waist')
# Bones the same length in every image (measured: sd 0.6-0.8 cm).
for name, b in d["bones"].items():
    if b["images"] < 12 or b["sd_m"] > 0.015: problems.append(f'{name}: {b}')
print("\n".join(problems), file=sys.stderr)
sys.exit(1 if problems else 0)
PY
ok "depth track on skeltrack-depth: $(json_get "$WORK/track.json" 'd["with_a_person"]') of 12 images with the person, $(json_get "$WORK/track.json" 'd["nearest_joints_on_person"]') of $(json_get "$WORK/track.json" 'd["nearest_joints_reported"]') joints on the person"

# ... and through fusion from the launch file (its pose assumed level: bringup/calib/depth_level.yaml).
"$S" launch "$SRC/bringup/depth_files.yaml" --set viewer.port=0 --duration 5 --json >"$WORK/launch.json" 2>"$WORK/launch.err" ||
  fail "depth_files.yaml: $(tail -3 "$WORK/launch.err")"
json_check "$WORK/launch.json" '[c for c in d["components"] if c["name"] == "depth_tracker"][0]["details"]["sensors"]["depth1"]["skeletons"] > 0'
python3 - "$WORK/launch.json" <<'PY' || fail "no fused skeleton from the real images: $(grep -h 'fusion' "$WORK/launch.err" | tail -2)"
import json, sys
d = {c["name"]: c for c in json.load(open(sys.argv[1]))["components"]}
sys.exit(0 if " 0 fused skeletons" not in d["fusion"]["summary"] else 1)
PY
ok "bringup/depth_files.yaml: real depth -> tracker -> fusion"
