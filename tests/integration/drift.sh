#!/usr/bin/env bash
# A sensor knocked out of place in a running graph (bringup/drift.yaml at
# twice the speed, the drift component's windows halved to match): sensor2
# turned by 3 degrees half a minute in (simulated time). The drift component
# reports sensor2 and only it, publishes its refined pose and says so (then
# OK: the poses agree again); without refine it ends DEGRADED naming sensor2;
# the same graph untouched ends OK with nothing reported.
source "$(dirname "$0")/lib.sh"
run() {  # run NAME BUMP REFINE DOMAIN_STEP (the three runs side by side, each on its own domain)
  SKELGRAPH_DOMAIN=$((${SKELGRAPH_DOMAIN:-0} + $4)) "$SKELGRAPH" launch "$SRC/bringup/drift.yaml" --duration 28 --json --set cell.rate=2 --set cell.bump="$2" \
    --set watch.refine="$3" --set watch.window_s=5 --set watch.settle_s=10 >"$WORK/$1.json" 2>"$WORK/$1.err" ||
    fail "launch ($1): $(tail -5 "$WORK/$1.err")"
}
run refined sensor2,30,3,0 true 0 &
run reported sensor2,30,3,0 false 1 &
run untouched "" true 2 &
wait
python3 - "$WORK/refined.json" "$WORK/reported.json" "$WORK/untouched.json" <<'PY' || fail "drift (above)"
import json, sys
def comps(path):
    return {c["name"]: c for c in json.load(open(path))["components"]}
refined, reported, untouched = (comps(p) for p in sys.argv[1:4])
problems = []
def check(cond, what):
    if not cond: problems.append(what)
w = refined["watch"]
r = w["details"]["refinements"]
check([x["sensor"] for x in r] == ["sensor2"] and r[0]["shift_cm"] >= 4.0, f"refined: {r}")
check(w["details"]["failed_writes"] == 0 and "refined sensor2" in w["message"], f"refined: {w['state']}: {w['message']}")
check(refined["fusion"]["state"] == "OK", f"refined: fusion {refined['fusion']['state']}")
w = reported["watch"]
sensors = {s["sensor"]: s for s in w["details"]["sensors"]}
check(w["state"] == "DEGRADED" and "sensor2 moved" in w["message"], f"reported: watch ended {w['state']}: {w['message']}")
check(sorted(s for s, v in sensors.items() if v["drifted"]) == ["sensor2"], f"reported: drifted {sensors}")
check(w["details"]["refined"] == 0, f"reported: refined without refine: {w['details']}")
u = untouched["watch"]
check(u["state"] == "OK" and "none moved" in u["message"], f"untouched: watch ended {u['state']}: {u['message']}")
check(all(p["baseline"] for p in u["details"]["pairs"]) and len(u["details"]["pairs"]) == 3, f"untouched: pairs {u['details']['pairs']}")
check(u["details"]["reports"] == 0 and u["details"]["refined"] == 0, f"untouched: {u['details']}")
for p in problems: print("  " + p)
if not problems:
    print(f"sensor2 reported ({sensors['sensor2']['shift_cm']:.1f} cm at the person); refined: {r}; untouched: OK")
sys.exit(1 if problems else 0)
PY
ok "a sensor turned by 3 degrees in a running graph is reported, and only it; with refine its pose is corrected; an untouched cell stays OK"
