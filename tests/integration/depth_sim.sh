#!/usr/bin/env bash
# The depth path end to end (bringup/depth_sim.yaml): the simulator's depth
# images of two sensors -> the open depth tracker -> kalman fusion -> gesture
# spotting, and the merged point cloud for viewers. Checks that every
# stage delivers, one person (no ghosts from walls), pointing events with floor
# targets, the cloud where the person is, and a tracker that waits for poses.
source "$(dirname "$0")/lib.sh"

"$SKELGRAPH" launch bringup/depth_sim.yaml --duration 60 --json >"$WORK/launch.json" 2>"$WORK/launch.err" &
graph=$!
# Two pointing events are what the checks below need: stop the graph once they are out.
"$SKELGRAPH" topic echo skelgraph/gesture/event --json --count 2 --timeout 55 >"$WORK/events.jsonl" 2>/dev/null &
echo_pid=$!
"$SKELGRAPH" topic echo skelgraph/cloud --count 1 --json --timeout 20 >"$WORK/cloud.json" || fail "no cloud"
for t in depth skeleton/raw skeleton/fused; do
  "$SKELGRAPH" topic hz "skelgraph/$t" --json --window 3 --timeout 10 >"$WORK/hz_${t//\//_}.json" || fail "no skelgraph/$t: $(tail -5 "$WORK/launch.err")"
done
wait "$echo_pid" || true
kill -INT "$graph"
wait "$graph" || fail "launch: $(tail -5 "$WORK/launch.err")"
# Every stage delivers (its rate on a busy machine is the benchmarks' business, not a test's).
for t in depth skeleton_raw skeleton_fused; do json_check "$WORK/hz_$t.json" 'd["samples"] >= 10'; done
python3 - "$WORK/launch.json" "$WORK/events.jsonl" <<'PY' || fail "graph report: $(cat "$WORK/launch.json")"
import json, sys
rep = {c["name"]: c for c in json.load(open(sys.argv[1]))["components"]}
for name in ("sim", "depth_tracker", "fusion", "gesture", "cloud"):
    assert rep[name]["state"] == "OK", (name, rep[name]["state"], rep[name].get("message"))
sim = rep["sim"]["details"]
assert sim["raw_published"] == 0 and sim["depth_published"] > 300, sim
trk = rep["depth_tracker"]["details"]["sensors"]
for s in ("sensor1", "sensor2"):
    t = trk[s]
    # The tracker takes the newest image when it is free, so how many it tracks before the
    # two pointing events is its speed (62 a sensor at 73 ms an image, a suite at -j6 beside it;
    # 366 and 362 at 7-9 ms when run alone): at least 40, the person in nearly every one.
    assert t["images"] >= 40 and t["skeletons"] >= 0.95 * t["images"], (s, t)
    assert t["skeletons"] <= t["images"], (s, t)                              # and nobody else
    assert t["people_started"] <= 2, (s, t)
events = [json.loads(l)["data"] for l in open(sys.argv[2]) if l.strip()]
points = [e for e in events if e["label"] == "point"]
assert len(points) >= 2, events
assert all(e["has_target"] and abs(e["target"]["y"]) < 1e-6 for e in points), points
assert len({e["person_id"] for e in points}) == 1, points
print("tracker:", {s: (trk[s]["images"], trk[s]["skeletons"], round(trk[s]["track_ms_per_image"], 1)) for s in trk},
      "points:", [(round(e["target"]["x"], 2), round(e["target"]["z"], 2)) for e in points])
PY
# The merged cloud of both sensors is the person: about their size, where they stand (the centre).
json_check "$WORK/cloud.json" 'd["data"]["source"] == "merged" and d["data"]["frame_id"] == "world" and d["data"]["points"] > 500 and 1.55 < d["data"]["max"][1] < 1.95 and d["data"]["min"][1] > 0.04 and all(-1.2 < d["data"][k][i] < 1.2 for k in ("min", "max") for i in (0, 2))'
ok "depth -> tracker -> fusion -> gesture; merged cloud of $(json_get "$WORK/cloud.json" 'd["data"]["points"]') points"

# Merged views: one tracker fitting both sensors' points, published as sensor "merged" in the world frame.
"$SKELGRAPH" run sim -p depth=true -p publish_raw=false -p scenario=point -p loop=true --duration 60 >/dev/null 2>"$WORK/sim3.err" &
sim3=$!
"$SKELGRAPH" run depth_tracker -p merge=true --duration 60 --json >"$WORK/merged.json" 2>"$WORK/merged.err" &
merged=$!
"$SKELGRAPH" topic echo skelgraph/skeleton/raw --count 1 --json --timeout 30 >"$WORK/merged_raw.json" || fail "no merged skeleton: $(cat "$WORK/merged.err")"
# 60 more merged skeletons (two seconds of fits), then both are stopped.
"$SKELGRAPH" topic echo skelgraph/skeleton/raw --count 60 --timeout 30 >/dev/null 2>&1 || fail "merged skeletons stopped: $(cat "$WORK/merged.err")"
kill -INT "$merged" "$sim3"
wait "$merged" || fail "merged tracker: $(cat "$WORK/merged.err")"
wait "$sim3" || true
json_check "$WORK/merged_raw.json" 'd["data"]["sensor_id"] == "merged" and d["data"]["frame_id"] == "world"'
json_check "$WORK/merged.json" 'd["components"][0]["state"] == "OK" and d["components"][0]["details"]["merged"]["fits"] >= 60 and d["components"][0]["details"]["merged"]["skeletons"] >= 0.95 * d["components"][0]["details"]["merged"]["fits"] and d["components"][0]["details"]["merged"]["skeletons"] <= d["components"][0]["details"]["merged"]["fits"]'
ok "merged views: $(json_get "$WORK/merged.json" 'd["components"][0]["summary"]')"

# Without poses (publish_poses off, no calibration) the tracker waits and says so.
"$SKELGRAPH" run sim -p depth=true -p publish_raw=false -p publish_poses=false -p sensor_count=1 -p loop=true \
  --duration 5 >/dev/null 2>"$WORK/sim2.err" &
sim2=$!
"$SKELGRAPH" run depth_tracker --duration 4 --json >"$WORK/waiting.json" 2>"$WORK/waiting.err" || fail "tracker: $(cat "$WORK/waiting.err")"
wait "$sim2" || true
json_check "$WORK/waiting.json" 'd["components"][0]["state"] == "DEGRADED" and "waiting for the pose of sensor1" in d["components"][0]["message"] and d["components"][0]["details"]["sensors"]["sensor1"]["skeletons"] == 0'
ok "no pose: tracker waits and says why"
