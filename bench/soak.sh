#!/usr/bin/env bash
# Soak benchmark: a simulated shift in which PLACES x REPEATS different people
# (default 4 x 50 = 200) come into the cell one after another, work and leave,
# watched by SENSORS sensors (default 3), run by the real graph over DDS (sim,
# fusion, gesture, recorder, viewer, presence; one process, a participant per
# component, loopback-only network namespace; bringup/shift.yaml) at RATE
# times real time (default 2.5: about 10.5 minutes). Reports,
# as JSON on stdout:
#  - presence: completeness per person against the truth, departures seen
#    (after the trackers let go of the person, and after the truth), failed
#    writes, live instances per writer against the people there;
#  - every component's final state and I/O counts;
#  - the recording: fused skeletons and distinct fused people it kept, against
#    what fusion published;
#  - the launch process's memory (VmRSS) sampled every minute, and its growth
#    from the second minute to the end.
# Exit 1 if a writer failed, a departure was missed or late, or instances of
# people who left stayed alive. tools/run bench writes build/bench/soak.json.
# Usage: bench/soak.sh BUILD_DIR [SENSORS] [PLACES] [REPEATS] [RATE]
set -euo pipefail
build=${1:?usage: soak.sh BUILD_DIR [SENSORS] [PLACES] [REPEATS] [RATE]}
sensors=${2:-3} places=${3:-4} repeats=${4:-50} rate=${5:-2.5}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$build/bench"
work=$(mktemp -d "$build/bench/soak.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$root/tests/netns-lo.sh" bash -s "$build" "$work" "$sensors" "$places" "$repeats" "$rate" "$root" <<'INNER'
set -euo pipefail
build=$1 work=$2 sensors=$3 places=$4 repeats=$5 rate=$6 root=$7
ip link set lo up
export SKELGRAPH_DOMAIN=78
sg="$build/bin/skelgraph"
start=$(date +%s)
"$sg" launch "$root/bringup/shift.yaml" --json \
  --set cell.people="$places" --set cell.repeats="$repeats" --set cell.sensor_count="$sensors" --set cell.rate="$rate" \
  --set recorder.directory="$work/rec" --set viewer.port=0 --set presence.people=true \
  >"$work/launch.json" 2>"$work/launch.err" &
pid=$!
# Memory of the whole graph's process, every minute (and once it has started).
: >"$work/rss.txt"
sample() { awk -v t=$(( $(date +%s) - start )) '/^VmRSS/ {print t, $2}' "/proc/$pid/status" >>"$work/rss.txt" 2>/dev/null || true; }
sleep 5
sample
next=60
while kill -0 "$pid" 2>/dev/null; do
  sleep 1
  if [ $(( $(date +%s) - start )) -ge "$next" ]; then
    sample
    next=$(( next + 60 ))
    echo "soak: $(( next / 60 - 1 )) min, VmRSS $(tail -1 "$work/rss.txt" | cut -d' ' -f2) kB" >&2
  fi
done
wait "$pid" || { echo "soak: launch failed:" >&2; tail -20 "$work/launch.err" >&2; exit 1; }
wall=$(( $(date +%s) - start ))
file=$(ls "$work"/rec/*.mcap | head -1)
"$sg" bag info "$file" --json >"$work/info.json"
"$sg" bag export "$file" --format generic --out "$work/export" --json >"$work/export.json"
python3 - "$work" "$wall" "$sensors" "$places" "$repeats" "$rate" <<'PY'
import csv, glob, json, os, sys
work, wall, sensors, places, repeats, rate = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
launch = json.load(open(os.path.join(work, "launch.json")))
comps = {c["name"]: c for c in launch["components"]}
presence = comps["presence"]["details"]
people = presence.pop("people_list")
info = json.load(open(os.path.join(work, "info.json")))
recorded = {t["topic"]: t["count"] for t in info["topics"]}
# Distinct fused people the recording kept (the generic CSV has a person column).
fused_ids = set()
for path in glob.glob(os.path.join(work, "export", "**", "*fused*"), recursive=True):
    with open(path) as f:
        for row in csv.DictReader(l for l in f if not l.startswith("#")):
            pid = row.get("person_id") or row.get("person")
            if pid is not None:
                fused_ids.add(pid)
rss = [tuple(map(int, l.split())) for l in open(os.path.join(work, "rss.txt")) if l.strip()]
after_warmup = [r for r in rss if r[0] >= 120]
growth = (after_warmup[-1][1] - after_warmup[0][1]) if len(after_warmup) >= 2 else None
fusion = comps["fusion"]
published_fused = fusion["details"]["published"]
ratios = sorted(p["shown_s"] / p["tracked_s"] for p in people if p["tracked_s"] >= 2.0)
out = {
    "config": {"sensors": sensors, "places": places, "people": places * repeats, "rate": rate},
    "wall_s": wall,
    "simulated_s": wall * rate,
    "presence": presence,
    "completeness_deciles": [ratios[int(q * (len(ratios) - 1))] for q in (0, 0.1, 0.5, 0.9, 1.0)] if ratios else None,
    "components": {n: {"state": c["state"], "message": c.get("message", ""), "io": c.get("io", "")} for n, c in comps.items()},
    "recording": {
        "fused_published": published_fused,
        "fused_recorded": recorded.get("skelgraph/skeleton/fused", 0),
        "fused_people_published": presence["fused"]["instances_seen"],
        "fused_people_recorded": len(fused_ids),
        "truth_recorded": recorded.get("skelgraph/skeleton/truth", 0),
    },
    "rss_kB": rss,
    "rss_growth_kB_from_minute_2": growth,
}
ok = (presence["failed_writes"] == 0 and presence["departures"]["late"] == 0 and presence["departures"]["still_shown"] == 0
      and presence["departures"]["not_seen"] == 0 and presence["people"]["seen"] >= places * repeats
      and all(o["instances"] == 0 for o in presence["outputs"]
              if o["topic"] in ("skelgraph/skeleton/fused", "skelgraph/skeleton/truth", "skelgraph/skeleton/raw", "skelgraph/gesture/state"))
      and all(c["state"] == "OK" for c in comps.values()))
out["ok"] = ok
print(json.dumps(out, indent=2))
sys.exit(0 if ok else 1)
PY
INNER
