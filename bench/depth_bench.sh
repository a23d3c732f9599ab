#!/usr/bin/env bash
# The depth path, measured. JSON on stdout (tools/run bench writes it to
# build/bench/depth_bench.json):
# - transport: two 640x480 uint16 depth streams at 30 Hz for SECONDS (default
#   30) from one process to another through the loopback profile (shared
#   memory), in a loopback-only network namespace: frames published, received,
#   missing, latency (median, p99, max);
# - tracker: `skelgraph eval sim --source depth` on walk, arms and point with
#   one sensor and with two (kalman fusion), 320x240: mean error per joint
#   group against the simulator's truth, and tracking time per image on one
#   thread (frames per second per sensor); and one tracker fitting both
#   sensors' merged clouds (--source depth-merged).
# Usage: bench/depth_bench.sh BUILD_DIR [SECONDS]
set -euo pipefail
build=${1:?usage: depth_bench.sh BUILD_DIR [SECONDS]}
seconds=${2:-30}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$root/tests/netns-lo.sh" bash -c '
  set -e
  ip link set lo up
  export SKELGRAPH_DOMAIN=78
  "$1/bench/stream_receive" $(( $2 + 4 )) depth >"$3/recv.json" & r=$!
  "$1/bench/publish_streams" 0 2 "$2" >"$3/pub.json"
  wait $r
' _ "$build" "$seconds" "$work"
"$build/bin/skelgraph" eval sim --source depth --scenarios walk,arms,point -p sensor_count=1 --methods kalman --json >"$work/one.json" 2>/dev/null
"$build/bin/skelgraph" eval sim --source depth --scenarios walk,arms,point -p sensor_count=2 --methods kalman,avg --json >"$work/two.json" 2>/dev/null
"$build/bin/skelgraph" eval sim --source depth-merged --scenarios walk,arms,point -p sensor_count=2 --methods kalman --json >"$work/merged.json" 2>/dev/null
python3 - "$work" <<'PY'
import json, sys
w = sys.argv[1]
pub, recv = json.load(open(w + "/pub.json")), json.load(open(w + "/recv.json"))
def rows(path):
    out = []
    for s in json.load(open(path))["scenarios"]:
        for st in s["streams"]:
            out.append({"scenario": s["scenario"], "sensors": s["sensors"], "stream": st["stream"],
                        "mean_error_cm": st["mean_error_cm"], "ticks_with_output": st["ticks_with_output"], "ticks": st["ticks"],
                        "groups": st["groups"], "track_ms_per_image": s["depth"]["track_ms_per_frame"],
                        "tracker_fps_one_thread": 1000.0 / s["depth"]["track_ms_per_frame"] if s["depth"]["track_ms_per_frame"] else None})
    return out
print(json.dumps({
    "transport": {"published": pub["depth"], "frame_bytes": pub["depth_frame_bytes"], "streams": recv["streams"],
                  "cpu_s": {"publisher": pub["cpu_s"], "receiver": recv["cpu_s"]},
                  "profile": "loopback (SHM 64 MiB segment, UDP 127.0.0.1 with 4 MiB buffers)"},
    "tracker": {"size": "320x240", "one_sensor": rows(w + "/one.json"), "two_sensors": rows(w + "/two.json"),
                "two_sensors_merged_clouds": rows(w + "/merged.json"),
                "note": "track_ms_per_image: tracking time over every image rendered; with merged clouds one fit takes both sensors' images"},
}, indent=2))
PY
