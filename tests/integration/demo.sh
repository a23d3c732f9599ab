#!/usr/bin/env bash
# The main job as a user runs it: `skelgraph demo` runs the live graph
# (simulated two-sensor cell, sync, recorder, fusion with every method),
# scores the session's recording, measures pointing on simulated sessions,
# evaluates the seven scenarios offline and writes one report.
source "$(dirname "$0")/lib.sh"

"$SKELGRAPH" demo --duration 6 --json --report "$WORK/report" >"$WORK/demo.json" 2>"$WORK/demo.err" ||
  fail "demo: $(tail -5 "$WORK/demo.err")"
grep -q "\[demo 5/5\]" "$WORK/demo.err" || fail "demo shows no progress: $(head -c 2000 "$WORK/demo.err")"
python3 - "$WORK/demo.json" <<'PY' || fail "demo report: $(head -c 3000 "$WORK/demo.json")"
import json, os, sys
d = json.load(open(sys.argv[1]))
assert os.path.getsize(d["report"]) > 10000, d["report"]
html = open(d["report"]).read()
for s in ("walk", "360", "hide", "box", "occ", "sit", "arms"):
    assert "<h2>%s (2 sensors" % s in html, s
    assert "<h2>%s (4 sensors" % s in html, s  # the 4-sensor ring's section
assert "<h1>Layout quarters:2</h1>" in html and "<h1>Layout ring:4</h1>" in html
assert "<h2>live graph" in html
assert "<h2>Pointing" in html
# The robot cell, judged against the truth: the arm never moved too close, it was stopped for the workers, and the timeline is drawn.
assert "<h2>Robot cell" in html and "The monitor's state" in html, "robot section"
r = d["robot"]
assert r["missed_steps"] == 0 and r["stops"] >= 1 and 0 < r["stop_pct"] < 100 and r["seconds"] > 20 and r["task_points_reached"] >= 1, r
assert os.path.exists(os.path.join(os.path.dirname(d["report"]), "robot_state.svg"))
p = d["pointing"]
assert p["truth"] == 24 and p["recall"] >= 0.8 and p["precision"] >= 0.8 and p["median_target_error_m"] < 0.4, p
assert p["quiet_hours"] > 0.2 and p["false_points_per_hour"] >= 0, p   # false alarms measured beside F1
# The operating curve: the given point first (the figures above), then stricter ones that find no more.
curve = p["operating_curve"]
assert len(curve) == 10 and curve[0]["min_confidence"] == 0 and curve[0]["confirm_s"] == 0, curve
assert abs(curve[0]["recall"] - p["recall"]) < 1e-9 and abs(curve[0]["false_per_hour"] - p["false_points_per_hour"]) < 1e-9, curve
assert curve[4]["recall"] <= curve[0]["recall"] and curve[4]["false_per_hour"] <= curve[0]["false_per_hour"], curve
assert os.path.exists(os.path.join(os.path.dirname(d["report"]), "pointing_curve.svg"))
assert "recall against false events per hour" in html
assert "false pointing events per hour" in open(d["report"]).read()
c = {x["name"]: x for x in d["components"]}
assert all(x["state"] == "OK" for x in c.values()), {k: (v["state"], v["message"]) for k, v in c.items()}
methods = ("avg", "sum", "facing", "weighted", "kalman")
for m in methods:
    det = c["fusion_" + m]["details"]
    assert det["published"] > 60 and det["tick_steps"] > 60, (m, det)
sess = d["seen"]["sessions"]
assert sess and sess[0]["ticks"] > 90 and sess[0]["saw_stop"], sess
assert os.path.exists(d["recording"]), d["recording"]
live = d["live_evaluation"]
assert live["on_sync_ticks"] and live["truth_skeletons"] > 100, live
streams = {s["stream"]: s for s in live["streams"]}
for m in methods:
    # Every method re-run offline and as recorded live, scored against the truth.
    for name in (m, "live " + m):
        assert streams[name]["ticks_with_output"] > 60 and streams[name]["mean_error_cm"] is not None, (name, streams.get(name))
# What the live kalman component published is what the offline re-run computes, give or take a tick.
off, on = streams["kalman"]["mean_error_cm"], streams["live kalman"]["mean_error_cm"]
assert abs(off - on) < 0.25 * off + 1.0, (off, on)
print("report %s; recording %s; kalman offline %.1f cm, live %.1f cm" % (d["report"], d["recording"], off, on))
PY
ok "demo: live graph (every method) recorded and scored, pointing, seven scenarios, one report"
