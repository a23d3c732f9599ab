#!/usr/bin/env bash
# The gesture component live: the launch file bringup/gesture_sim.yaml (the
# simulated cell pointing, fusion, gesture with a classifier trained at start
# on simulated sessions) prints pointing events with their floor targets and
# publishes events and states that a second process reads over DDS. Then the
# offline measurement `skelgraph gesture sim --json` on held-out sessions.
source "$(dirname "$0")/lib.sh"
S=$SKELGRAPH
cd "$SKELGRAPH_SOURCE_DIR"

"$S" topic echo skelgraph/gesture/event --json --count 2 --timeout 60 >"$WORK/events.json" 2>"$WORK/echo.err" &
echo_pid=$!
# Every state the component publishes (on each change and once a second), until the launch ends.
"$S" topic echo skelgraph/gesture/state --json --timeout 60 >"$WORK/states.json" 2>"$WORK/echo_state.err" &
state_pid=$!
"$S" launch bringup/gesture_sim.yaml --duration 90 --json >"$WORK/launch.json" 2>"$WORK/launch.err" &
launch=$!
# Three pointing events in the log are what the checks need: then the graph is stopped.
wait_for_count "$WORK/launch.err" "point by person 1 (.* arm) at floor" 3 80
kill -INT "$launch"
wait "$launch" || fail "launch: $(tail -5 "$WORK/launch.err")"
wait "$echo_pid" || fail "topic echo saw no gesture events: $(cat "$WORK/echo.err")"
n=$(grep -c "point by person 1 (.* arm) at floor" "$WORK/launch.err" || true)
[ "$n" -ge 3 ] || fail "expected at least 3 pointing events with floor targets in the log, got $n: $(grep gesture "$WORK/launch.err" | tail -5)"
json_check "$WORK/launch.json" 'any(c["name"] == "gesture" and c["details"]["by_label"].get("point", 0) >= 3 for c in d["components"])'
python3 - "$WORK/events.json" <<'PY' || fail "gesture events over DDS"
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
assert len(lines) >= 2, lines
for l in lines:
    e = l.get("data", l)
    assert e["label"] == "point" and e["person_id"] == 1, e
    assert e["has_ray"] and 0 <= e["confidence"] <= 1 and e["end_stamp_ns"] >= e["start_stamp_ns"], e
    if e["has_target"]:
        assert e["target_name"] == "floor" and abs(e["target"]["y"]) < 1e-6, e
PY
ok "live: $n pointing events with floor targets, read over DDS too"

kill -TERM "$state_pid" 2>/dev/null || true
wait "$state_pid" || fail "topic echo saw no gesture states: $(cat "$WORK/echo_state.err")"
python3 - "$WORK/states.json" "$WORK/events.json" <<'PY' || fail "gesture states over DDS"
import json, sys
states = [json.loads(l).get("data") for l in open(sys.argv[1]) if l.strip()]
events = [json.loads(l).get("data") for l in open(sys.argv[2]) if l.strip()]
# At least one a second while the person is watched, and more on every change.
assert len(states) >= 10, len(states)
for s in states:
    assert s["state"] in ("resting", "moving", "holding"), s
    assert s["person_id"] >= 1 and s["source"] and s["stamp_ns"] > 0, s
seen = {s["state"] for s in states}
assert seen == {"resting", "moving", "holding"}, seen  # arms down between gestures, waves and stretches, pointing
# Skeleton stamps never go back (one writer, reliable: in order).
stamps = [s["stamp_ns"] for s in states]
assert all(a <= b for a, b in zip(stamps, stamps[1:])), stamps
# Each pointing event read over DDS came with its person holding still during the gesture.
for e in events:
    held = [s for s in states if s["person_id"] == e["person_id"] and s["source"] == e["source"] and s["state"] == "holding"
            and e["start_stamp_ns"] <= s["stamp_ns"] <= e["end_stamp_ns"]]
    assert held, (e, [(s["stamp_ns"], s["state"]) for s in states])
print(len(states), "states:", ", ".join(f"{k} {sum(s['state'] == k for s in states)}" for k in ("resting", "moving", "holding")))
PY
ok "live: gesture states read over DDS, 'holding' during each pointing event"

"$S" gesture sim --train-sessions 4 --train-quiet-sessions 2 --test-sessions 2 --json >"$WORK/sim.json" 2>/dev/null || fail "gesture sim"
json_check "$WORK/sim.json" 'd["spotting"]["truth"] == 12 and d["spotting"]["recall"] >= 0.8 and d["spotting"]["median_target_error_m"] < 0.4'
# False alarms: a session of each scenario where nobody gestures, every event counted against its hours.
python3 - "$WORK/sim.json" <<'PY' || fail "false alarms: $(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["false_alarms"])' "$WORK/sim.json")"
import json, sys
q = json.load(open(sys.argv[1]))["false_alarms"]
names = [s["scenario"] for s in q["scenarios"]]
assert names == ["walk", "360", "hide", "box", "occ", "sit", "arms", "work"], names
assert all(s["seconds"] > 10 for s in q["scenarios"]), q["scenarios"]
assert abs(q["hours"] - sum(s["seconds"] for s in q["scenarios"]) / 3600) < 1e-9, q
for label, n in q["events"].items():
    assert n == sum(s["events"].get(label, 0) for s in q["scenarios"]), (label, q)
    assert abs(q["per_hour"][label] - n / q["hours"]) < 1e-6, (label, q)
assert "point" in q["per_hour"], q
# The operating curve: the options given first (the figures above), then each point spotted again.
d = json.load(open(sys.argv[1]))
c = d["operating_curve"]
assert len(c) == 10 and (c[0]["min_confidence"], c[0]["confirm_s"]) == (0, 0), c
assert c[0]["recall"] == d["spotting"]["recall"] and abs(c[0]["false_per_hour"] - q["per_hour"]["point"]) < 1e-9, c
assert [p["confirm_s"] for p in c] == [0] * 5 + [0.5] * 5, c
print("false pointing events per hour: %.1f over %.2f h (%s)" % (q["per_hour"]["point"], q["hours"],
      ", ".join("%s %d" % (s["scenario"], s["events"].get("point", 0)) for s in q["scenarios"])))
PY
ok "offline: held-out simulated sessions scored, false alarms counted in eight scenarios without gestures"

# The same sessions without the trackers' random errors: the targets land
# within a few centimetres (what is left at noise 1 is the trackers' noise).
"$S" gesture sim --train-sessions 4 --train-quiet-sessions 0 --test-sessions 2 --test-noise-scale 0 --quiet-sessions 0 --json >"$WORK/sim0.json" 2>/dev/null || fail "gesture sim --test-noise-scale 0"
python3 - "$WORK/sim.json" "$WORK/sim0.json" <<'PY' || fail "noise-free test sessions"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
assert b["test_noise_scale"] == 0 and a["test_noise_scale"] == 1, (a["test_noise_scale"], b["test_noise_scale"])
s0, s1 = b["spotting"], a["spotting"]
assert s0["truth"] == 12 and s0["recall"] >= 0.8, s0
assert s0["median_target_error_m"] < 0.08 and s0["median_target_error_m"] < s1["median_target_error_m"], (s0["median_target_error_m"], s1["median_target_error_m"])
# The whole-hold reference: one per true pointing hold, and as close without the noise.
r0, r1 = b["whole_hold_reference"], a["whole_hold_reference"]
assert r0["holds"] == r1["holds"] == s0["truth"], (r0["holds"], r1["holds"], s0["truth"])
assert r0["median_target_error_m"] < 0.08 and r0["median_target_error_m"] < r1["median_target_error_m"], (r0, r1)
assert r0["within_15_cm"] <= r0["holds"] and b["spotted_within_15_cm"] <= s0["true_positive"], (r0, b["spotted_within_15_cm"])
print("median target error, noise 1 -> 0: %.1f -> %.1f cm" % (100 * s1["median_target_error_m"], 100 * s0["median_target_error_m"]))
PY
ok "offline: without the trackers' noise the targets are within a few cm"

# Parameters from the command line: surfaces as a comma-split list, and clear errors.
"$S" run gesture -p model=sim -p surfaces=table:0,0.75,0,floor:0,0,0 --duration 0.5 >/dev/null 2>"$WORK/run.err" \
  || fail "run gesture with two surfaces: $(tail -3 "$WORK/run.err")"
"$S" run gesture -p model=sim -p surfaces=table:0,0.75 --duration 0.5 2>"$WORK/bad.err" && fail "a surface with two numbers was accepted"
grep -q "surface 'table:0,0.75': expected x,y,z" "$WORK/bad.err" || fail "surface error: $(cat "$WORK/bad.err")"
"$S" run gesture --duration 0.5 2>"$WORK/bad.err" && fail "no model was accepted"
grep -q "model: no classifier given" "$WORK/bad.err" || fail "missing model error: $(cat "$WORK/bad.err")"
ok "command-line surfaces and clear errors for bad parameters"
