#!/usr/bin/env bash
# End-to-end latency of the fused skeleton and of the gesture state, with a
# bare Fast DDS hop measured in the same run (issue 31). JSON on stdout
# (tools/run bench writes build/bench/latency_bench.json).
# For 2 and 4 simulated sensors, 1 and 3 people, fusion on sync ticks and on
# arrival: one process runs the graph (sim, sync_master, fusion kalman,
# gesture), bench/latency_probe receives everything as a robot would while a
# second latency_probe sends Skeleton-sized messages on skelgraph/bench/hop.
# Latencies: receipt minus the newest (and oldest) input's capture stamp;
# `over_hop_p99_ms` = fused p99 after the newest capture minus the raw path's
# p99 (the input's own hop) minus the bare hop's p99: what fusion adds beyond
# one more hop. The fusion component's compute time per step is reported.
# Loopback only (its own network namespace).
# Usage: bench/latency_bench.sh BUILD_DIR [SECONDS_PER_RUN]
set -euo pipefail
build=$(cd "${1:?usage: latency_bench.sh BUILD_DIR [SECONDS_PER_RUN]}" && pwd)
seconds=${2:-12}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$root"
runs=()
for sensors in 2 4; do
  for people in 1 3; do
    for trigger in ticks arrival; do
      name="s${sensors}_p${people}_${trigger}"
      cat >"$work/$name.yaml" <<YAML
components:
  - {name: sync, type: sync_master, params: {tick_period_ms: 33}}
  - {name: sim, type: sim, params: {scenario: point, people: $people, sensor_count: $sensors, layout: ring, loop: true}}
  - {name: fusion, type: fusion, params: {method: kalman, trigger: $trigger}}
  - {name: gesture, type: gesture, params: {model: sim, surfaces: ["floor:0,0,0"]}}
YAML
      runs+=("$name")
    done
  done
done
"$root/tests/netns-lo.sh" bash -s "$build" "$seconds" "$work" "${runs[@]}" <<'INNER'
set -euo pipefail
build=$1 seconds=$2 work=$3
shift 3
ip link set lo up
for name in "$@"; do
  "$build/bin/skelgraph" launch "$work/$name.yaml" --duration "$seconds" --json >"$work/$name.launch.json" 2>"$work/$name.err" &
  launch=$!
  sleep 3  # discovery, the gesture model, the first session
  probe_s=$((seconds - 5))
  "$build/bench/latency_probe" send "$probe_s" >/dev/null &
  "$build/bench/latency_probe" receive "$probe_s" >"$work/$name.probe.json"
  wait
  echo "latency_bench: $name done" >&2
done
INNER
python3 - "$work" "$seconds" "${runs[@]}" <<'PY'
import json, sys
work, seconds, names = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
out = {"seconds_per_run": seconds, "runs": []}
for name in names:
    probe = json.load(open(f"{work}/{name}.probe.json"))
    comps = {c["name"]: c for c in json.load(open(f"{work}/{name}.launch.json"))["components"]}
    f = comps["fusion"]["details"]
    s, p, trig = name.split("_")
    r = {"sensors": int(s[1:]), "people": int(p[1:]), "trigger": trig, **probe,
         "fusion_compute_us": f["compute_us"], "fusion_steps": f["steps"],
         "arrival_steps": f["arrival_steps"], "arrival_waited_out": f["arrival_waited_out"],
         "over_hop_p99_ms": probe["fused_newest_ms"]["p99"] - probe["raw_ms"]["p99"] - probe["hop_ms"]["p99"],
         "ratio_p99_to_hop": probe["fused_newest_ms"]["p99"] / max(1e-9, probe["hop_ms"]["p99"])}
    out["runs"].append(r)
json.dump(out, sys.stdout, indent=1)
print()
PY
