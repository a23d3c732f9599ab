#!/usr/bin/env bash
# Offline fusion + evaluation throughput: a two-sensor simulated session of
# about MINUTES minutes (default 60; the `walk` scenario repeated) generated,
# fused with all five methods plus each single sensor, and scored against the
# truth, single-threaded, as `skelgraph eval sim` does. Reports wall time,
# the real-time factor and peak memory. JSON on stdout (tools/run bench writes
# it to build/bench/fusion_bench.json). No DDS.
# Usage: bench/fusion_bench.sh BUILD_DIR [MINUTES]
set -euo pipefail
build=${1:?usage: fusion_bench.sh BUILD_DIR [MINUTES]}
minutes=${2:-60}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# walk runs 18.7 s per repeat.
repeats=$(python3 -c "import math; print(max(1, math.ceil($minutes * 60 / 18.7)))")
python3 - "$build/bin/skelgraph" "$repeats" "$work" <<'PY'
import json, resource, subprocess, sys, time
sg, repeats, work = sys.argv[1], int(sys.argv[2]), sys.argv[3]
t0 = time.monotonic()
out = subprocess.run([sg, "eval", "sim", "--scenarios", "walk", "-p", "repeats=%d" % repeats, "--json"],
                     check=True, capture_output=True, text=True).stdout
wall = time.monotonic() - t0
ru = resource.getrusage(resource.RUSAGE_CHILDREN)
d = json.loads(out)["scenarios"][0]
ticks = d["ticks"]
sim_s = ticks / 30.0
print(json.dumps({
    "bench": "offline fusion + evaluation (skelgraph eval sim, walk x %d)" % repeats,
    "sensors": d["sensors"],
    "streams": [s["stream"] for s in d["streams"]],
    "output_ticks": ticks,
    "session_s": round(sim_s, 1),
    "wall_s": round(wall, 2),
    "cpu_s": round(ru.ru_utime + ru.ru_stime, 2),
    "real_time_factor": round(sim_s / wall, 1),
    "peak_rss_mb": round(ru.ru_maxrss / 1024.0, 1),
    "note": "one thread; includes simulating the session; simulated and scored a minute at a time (the evaluation holds the last 2 s)",
}, indent=2))
PY
