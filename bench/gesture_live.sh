#!/usr/bin/env bash
# Pointing live, measured: runs bringup/gesture_sim.yaml (simulated cell ->
# Kalman fusion -> gesture) for SECONDS (default 60) in a loopback-only
# network namespace, records every gesture event and the ground-truth
# skeletons over DDS with `skelgraph topic echo`, and scores each pointing
# event's floor target against where the true shoulder -> hand ray of the
# same arm met the floor while that arm was held still near the event's
# stamp. JSON on stdout: per event the error, and the median. Needs root for
# tests/netns-lo.sh. NOISE_SCALE (default 1) scales the simulated trackers' random
# errors (the sim's noise_scale; 0 leaves the skeleton convention's offsets,
# the lag and the geometry): how far the targets are off without that noise.
# SCENARIO (default point) runs another simulator scenario instead; in one
# where nobody gestures (walk, 360, hide, box, occ, sit, arms, work) every
# event is a false alarm, reported per hour (false_events_per_hour).
# Usage: bench/gesture_live.sh BUILD_DIR [SECONDS] [NOISE_SCALE] [SCENARIO]
set -euo pipefail
build=${1:?usage: gesture_live.sh BUILD_DIR [SECONDS] [NOISE_SCALE] [SCENARIO]}
seconds=${2:-60}
noise=${3:-1}
scenario=${4:-point}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sg="$build/bin/skelgraph"
launch="$root/bringup/gesture_sim.yaml"
if [[ "$noise" != 1 || "$scenario" != point ]]; then
  launch="$work/gesture_sim.yaml"
  sed "s/^      loop: true\$/      loop: true\n      noise_scale: $noise/; s/^      scenario: point\$/      scenario: $scenario/" \
    "$root/bringup/gesture_sim.yaml" >"$launch"
  grep -q "noise_scale: $noise" "$launch" && grep -q "scenario: $scenario" "$launch" ||
    { echo "gesture_live.sh: could not set noise_scale and scenario in $launch" >&2; exit 2; }
fi
"$root/tests/netns-lo.sh" bash -c '
  set -e
  ip link set lo up
  cd "$1"
  "$2" topic echo skelgraph/skeleton/truth --json --timeout 120 >"$3/truth.json" & tp=$!
  "$2" topic echo skelgraph/gesture/event --json --timeout 120 >"$3/events.json" & ep=$!
  "$2" launch "$5" --duration "$4" >"$3/launch.json" 2>"$3/launch.err"
  sleep 1
  kill $tp $ep 2>/dev/null || true
' _ "$root" "$sg" "$work" "$seconds" "$launch"
python3 - "$work" "$seconds" "$noise" "$scenario" <<'PY'
import bisect, json, math, statistics, sys
work, seconds, noise, scenario = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
truth = [json.loads(l)["data"] for l in open(work + "/truth.json") if l.strip()]
events = [json.loads(l)["data"] for l in open(work + "/events.json") if l.strip()]
stamps = [t["stamp_ns"] for t in truth]
def joint(t, name):
    p = next(j["position"] for j in t["joints"] if j["name"] == name)
    return (p["x"], p["y"], p["z"])
out, errors = [], []
for e in events:
    row = {"label": e["label"], "arm": e["arm"], "confidence": e["confidence"], "has_target": e["has_target"]}
    if e["label"] == "point" and e["has_target"] and truth:
        # The true target is where the true arm pointed while it was held
        # still (hand slower than 5 cm/s) within 2 s of the event's stamp;
        # an event sent early or as the arm starts back down is scored
        # against the hold, not against a moving arm.
        i = min(range(len(stamps)), key=lambda k: abs(stamps[k] - e["end_stamp_ns"]))
        def ray_hit(k):
            sh, ha = joint(truth[k], e["arm"] + "_shoulder"), joint(truth[k], e["arm"] + "_hand")
            d = [b - a for a, b in zip(sh, ha)]
            return [a + (-sh[1] / d[1]) * b for a, b in zip(sh, d)] if d[1] < 0 else None, d
        def held(k):
            if k < 1 or k >= len(truth) or stamps[k] <= stamps[k - 1]:
                return False
            ha, ha0 = joint(truth[k], e["arm"] + "_hand"), joint(truth[k - 1], e["arm"] + "_hand")
            hit, d = ray_hit(k)
            speed = math.dist(ha, ha0) / ((stamps[k] - stamps[k - 1]) * 1e-9)
            return hit is not None and speed < 0.05 and -d[1] < 0.9 * math.hypot(*d)  # still, down, not hanging
        # the run of held frames nearest the stamp (within 2 s)
        near = next((k for r in range(61) for k in (i - r, i + r) if held(k)), None)
        hits = []
        if near is not None:
            a = b = near
            while held(a - 1): a -= 1
            while held(b + 1): b += 1
            hits = [ray_hit(k)[0] for k in range(a, b + 1)]
        elif ray_hit(i)[0] is not None:
            hits = [ray_hit(i)[0]]
        if hits:
            tt = [statistics.median(h[c] for h in hits) for c in range(3)]
            err = math.dist(tt, [e["target"]["x"], e["target"]["y"], e["target"]["z"]])
            row.update(true_target=tt, target=[e["target"][c] for c in "xyz"], error_m=err, held_frames=len(hits))
            errors.append(err)
    out.append(row)
result = {"scenario": scenario, "seconds": seconds, "noise_scale": noise, "events": len(events), "scored": len(errors),
          "median_target_error_m": statistics.median(errors) if errors else None,
          "within_15_cm": sum(e <= 0.15 for e in errors), "per_event": out}
if scenario != "point":  # nobody gestures: every event is a false alarm
    result["false_events_per_hour"] = {l: 3600.0 * sum(e["label"] == l for e in events) / seconds for l in sorted({e["label"] for e in events})}
print(json.dumps(result, indent=2))
PY
