#!/usr/bin/env bash
# The robot in the cell (issue 32, first part): bringup/robot_cell.yaml runs a
# simulated arm working beside a walking worker with speed-and-separation monitoring;
# the verdicts are published and obeyed (the robot is slowed and stopped, and
# resumes). Fail-safes: with no people data, and with no robot state, the
# verdict is a protective stop saying why. A stop gesture stops it too.
#   robot.sh SKELGRAPH PUBLISH_GESTURE
source "$(dirname "$0")/lib.sh"
PUBLISH_GESTURE=${2:?publish_gesture}

"$SKELGRAPH" topic echo skelgraph/safety --json >"$WORK/safety.jsonl" 2>/dev/null &
echo_pid=$!
"$SKELGRAPH" launch bringup/robot_cell.yaml --duration 12 --json >"$WORK/cell.json" 2>"$WORK/cell.err" ||
  fail "robot_cell: $(tail -5 "$WORK/cell.err")"
kill "$echo_pid" 2>/dev/null || true
wait "$echo_pid" 2>/dev/null || true
python3 - "$WORK/cell.json" "$WORK/safety.jsonl" <<'PY' || fail "robot cell: $(head -c 3000 "$WORK/cell.json")"
import json, sys
d = {c["name"]: c for c in json.load(open(sys.argv[1]))["components"]}
sep, robot = d["separation"]["details"], d["robot"]["details"]
by = sep["steps_by_state"]
# The arm works round its task points; the worker walks close by: the monitor slows and stops it, and lets it go again.
assert robot["task_points_reached"] >= 1, robot
# The simulated sensors see the arm's links (they hide the worker behind them).
assert d["sim"]["details"]["robot_links_hiding"] == 7, d["sim"]["details"]
assert by.get("PROTECTIVE_STOP", 0) > 0 and by.get("RUN", 0) + by.get("REDUCED", 0) > 0, by
# (the last command or two may be sent while the graph shuts down)
assert sep["failed_writes"] == 0 and robot["protective_stops"] >= 1 and sep["commands"] - 2 <= robot["commands"] <= sep["commands"], (sep, robot)
# The reaction time is measured: the people data's age (the trackers' 50 ms lag included) plus compute and command latency.
r = sep["reaction_ms"]
assert r["n"] > 100 and 60 < r["p50"] < 200, r
rows = [json.loads(l)["data"] for l in open(sys.argv[2])]
states = {x["state"] for x in rows}
assert {"PROTECTIVE_STOP"} < states, states
near = [x for x in rows if x["state"] == "PROTECTIVE_STOP" and x["separation_m"] is not None and x["separation_m"] >= 0]
assert all(x["protective_m"] is not None for x in near), [x for x in near if x["protective_m"] is None][:3]
# Every stop has its reason: too close, or a fail-safe one (a busy machine delays frames: data too old, a
# sensor lost, a person not placed), and the hold after either.
justified = ("no useful speed", "holding the stop", "is lost and no other covers it", "ms old (limit", "fusion cannot place")
unjustified = [x for x in near if not (x["separation_m"] < x["protective_m"] + 0.3 + 1e-6 or any(j in x["reason"] for j in justified))]
assert near and not unjustified, unjustified[:3]
assert all(x["body_part"] and x["robot_part"] for x in near), near[:3]
print("ok: robot cell: %s; reaction p50 %.0f ms; %d protective stops" % (by, r["p50"], robot["protective_stops"]))
PY

# Following a hand (bringup/robot_follow.yaml): targets are sent and obeyed, holds when there is no hand.
"$SKELGRAPH" launch bringup/robot_follow.yaml --duration 8 --json >"$WORK/follow.json" 2>"$WORK/follow.err" ||
  fail "robot_follow: $(tail -5 "$WORK/follow.err")"
python3 - "$WORK/follow.json" <<'PY' || fail "robot follow: $(head -c 3000 "$WORK/follow.json")"
import json, sys
d = {c["name"]: c for c in json.load(open(sys.argv[1]))["components"]}
f, robot, sep = d["follow"]["details"], d["robot"]["details"], d["separation"]["details"]
assert d["follow"]["state"] == "OK" and f["failed_writes"] == 0, d["follow"]
# The worker's hand is tracked most of the time: targets go out and the robot takes them (with the monitor's commands).
assert f["following_steps"] > f["steps"] // 2 and f["moves"] >= 2, f
assert robot["commands"] >= f["moves"] + f["holds"] - 2 and robot["ignored"] == 0, (f, robot)
assert sep["steps_by_state"].get("PROTECTIVE_STOP", 0) > 0, sep
print("ok: follow: %d of %d steps following, %d targets, %d holds; monitor %s" % (f["following_steps"], f["steps"], f["moves"], f["holds"], sep["steps_by_state"]))
PY

# The robot's topics are recorded like the others and replayed (bag play) as they were.
cat >"$WORK/robot_rec.yaml" <<YAML
components:
  - {name: sim, type: sim, params: {scenario: robot, layout: ring, sensor_count: 4, loop: true}}
  - {name: fusion, type: fusion, params: {method: kalman, trigger: arrival}}
  - {name: robot, type: robot, params: {robot_id: robot1, base: "0,0,1.9,180", task: ["0.45,0.6,1.5", "-0.45,0.6,1.5"]}}
  - {name: separation, type: separation, params: {robot_id: robot1}}
  - {name: recorder, type: recorder, params: {directory: "$WORK/rec", now: true}}
YAML
"$SKELGRAPH" launch "$WORK/robot_rec.yaml" --duration 4 >/dev/null 2>"$WORK/rec.err" || fail "robot recording: $(tail -5 "$WORK/rec.err")"
rec=$(ls "$WORK"/rec/*.mcap | head -1)
"$SKELGRAPH" bag info "$rec" --json >"$WORK/rec_info.json" || fail "bag info $rec"
n_state=$(python3 -c 'import json,sys; print({t["topic"]: t["count"] for t in json.load(open(sys.argv[1]))["topics"]}.get("skelgraph/robot/state", 0))' "$WORK/rec_info.json")
n_safety=$(python3 -c 'import json,sys; print({t["topic"]: t["count"] for t in json.load(open(sys.argv[1]))["topics"]}.get("skelgraph/safety", 0))' "$WORK/rec_info.json")
# The recording played in a loop until the readers have as many samples as it holds (each echo ends at its count).
"$SKELGRAPH" topic echo skelgraph/robot/state --json --count "$n_state" --timeout 60 >"$WORK/replayed_state.jsonl" 2>/dev/null &
echo_pid=$!
"$SKELGRAPH" topic echo skelgraph/safety --json --count "$n_safety" --timeout 60 >"$WORK/replayed_safety.jsonl" 2>/dev/null &
echo2_pid=$!
"$SKELGRAPH" bag play "$rec" --loop --topics skelgraph/robot/state skelgraph/safety >/dev/null 2>&1 &
play_pid=$!
wait "$echo_pid" "$echo2_pid" || true
kill "$play_pid" 2>/dev/null || true
wait "$play_pid" 2>/dev/null || true
python3 - "$WORK/rec_info.json" "$WORK/replayed_state.jsonl" "$WORK/replayed_safety.jsonl" <<'PY' || fail "robot topics recorded and replayed"
import json, sys
topics = {t["topic"]: t["count"] for t in json.load(open(sys.argv[1]))["topics"]}
assert topics.get("skelgraph/robot/state", 0) > 200 and topics.get("skelgraph/safety", 0) > 10 and topics.get("skelgraph/robot/command", 0) >= 1, topics
state = [json.loads(l)["data"] for l in open(sys.argv[2])]
safety = [json.loads(l)["data"] for l in open(sys.argv[3])]
# As many samples as recorded come back, as recorded.
assert len(state) == topics["skelgraph/robot/state"] and all(s["robot_id"] == "robot1" and len(s["capsules"]) == 7 for s in state), len(state)
assert len(safety) == topics["skelgraph/safety"] and all(x["robot_id"] == "robot1" and x["state"] for x in safety), (len(safety), topics["skelgraph/safety"])
print("ok: robot topics recorded (%s) and replayed (%d states, %d safety verdicts)" % (
    {k: v for k, v in topics.items() if "robot" in k or "safety" in k}, len(state), len(safety)))
PY

# Pointing to fetch: pointing events at (1.4, 0, 0) (publish_gesture), a robot standing 0.7 m from that
# spot; sensors alive and nobody in the cell (no fusion), so the monitor says RUN: the tool goes to hover above it.
cat >"$WORK/fetch.yaml" <<'YAML'
components:
  - {name: sim, type: sim, params: {scenario: walk, sensor_count: 2, loop: true}}
  - {name: robot, type: robot, params: {robot_id: robot1, base: "1.4,0,0.7,180"}}
  - {name: separation, type: separation, params: {robot_id: robot1}}
  - {name: fetch, type: fetch, params: {robot_id: robot1, base: "1.4,0,0.7,180", label: pointing}}
YAML
"$SKELGRAPH" launch "$WORK/fetch.yaml" --duration 15 --json >"$WORK/fetch.json" 2>"$WORK/fetch.err" &
fetch_launch=$!
wait_for_match "$WORK/fetch.err" "\[start\] fetch" 20 || fail "fetch did not start: $(tail -5 "$WORK/fetch.err")"
"$PUBLISH_GESTURE" 6 2>/dev/null
wait "$fetch_launch" || fail "fetch launch: $(tail -5 "$WORK/fetch.err")"
python3 - "$WORK/fetch.json" <<'PY' || fail "fetch: $(head -c 3000 "$WORK/fetch.json")"
import json, math, sys
d = {c["name"]: c for c in json.load(open(sys.argv[1]))["components"]}
f, robot = d["fetch"]["details"], d["robot"]["details"]
assert f["events"] >= 8 and f["sent"] == 1 and f["out_of_reach"] == 0 and f["failed_writes"] == 0, f
assert f["repeats"] + f["not_run"] + f["sent"] == f["events"], f
assert math.dist(f["target"], [1.4, 0.15, 0.0]) < 1e-6, f
# The arm went there.
assert math.dist(robot["tool"], f["target"]) < 0.03, (robot["tool"], f["target"])
print("ok: fetch: %d pointing events, the tool sent once to hover above the spot and now %.3f m from it" % (f["events"], math.dist(robot["tool"], f["target"])))
PY

# The offline measurements as a user runs them (short), and bad input said plainly.
"$SKELGRAPH" eval safety --seeds 1 --people 2 --repeats 1 --dropout sensor2,10,3 --json >"$WORK/safety.json" 2>/dev/null || fail "eval safety"
json_check "$WORK/safety.json" 'len(d["runs"]) == 1 and d["runs"][0]["people"] == 2 and d["total"]["seconds"] > 10 and d["total"]["missed_steps"] == 0 and d["total"]["stops"] >= 1'
"$SKELGRAPH" eval fetch --sessions 2 --json >"$WORK/fetch_eval.json" 2>/dev/null || fail "eval fetch"
json_check "$WORK/fetch_eval.json" 'd["pointing"] == 12 and d["fetched"] <= d["spotted"] <= d["in_reach"] <= d["pointing"]'
for bad in "--dropout sensor9,10,3" "--dropout sensor1,3,10" "-p sensor_count=2 -p sensor_count=3"; do
  # shellcheck disable=SC2086
  if "$SKELGRAPH" eval safety --repeats 1 $bad >/dev/null 2>"$WORK/bad.err"; then fail "eval safety $bad was accepted"; fi
  grep -q "error:" "$WORK/bad.err" || fail "eval safety $bad: no error message: $(cat "$WORK/bad.err")"
done
ok "eval safety and eval fetch: JSON as documented; bad --dropout and parameters refused with a message"

# Fail-safe: a robot and its monitor with no sensors at all.
cat >"$WORK/no_people.yaml" <<'YAML'
components:
  - {name: robot, type: robot}
  - {name: separation, type: separation}
YAML
"$SKELGRAPH" launch "$WORK/no_people.yaml" --duration 2 --json >"$WORK/no_people.json" 2>/dev/null || fail "no_people launch"
json_check "$WORK/no_people.json" '[c for c in d["components"] if c["name"] == "separation"][0]["details"]["steps_by_state"] == {"PROTECTIVE_STOP": [c for c in d["components"] if c["name"] == "separation"][0]["details"]["steps"]} and "no people data" in [c for c in d["components"] if c["name"] == "separation"][0]["details"]["reason"]'
ok "no people data: protective stop throughout"

# Fail-safe: people data but no robot state.
cat >"$WORK/no_robot.yaml" <<'YAML'
components:
  - {name: sim, type: sim, params: {scenario: walk, sensor_count: 2, loop: true}}
  - {name: fusion, type: fusion, params: {method: kalman, trigger: arrival}}
  - {name: separation, type: separation}
YAML
"$SKELGRAPH" launch "$WORK/no_robot.yaml" --duration 3 --json >"$WORK/no_robot.json" 2>/dev/null || fail "no_robot launch"
json_check "$WORK/no_robot.json" '[c for c in d["components"] if c["name"] == "separation"][0]["details"]["steps_by_state"] == {"PROTECTIVE_STOP": [c for c in d["components"] if c["name"] == "separation"][0]["details"]["steps"]} and "robot state" in [c for c in d["components"] if c["name"] == "separation"][0]["details"]["reason"]'
ok "no robot state: protective stop throughout"

# A stop gesture stops the robot, though nobody is near it (the arm stands 8 m from the walking
# worker), for gesture_stop_s; then it runs again.
cat >"$WORK/gesture_stop.yaml" <<'YAML'
components:
  - {name: sim, type: sim, params: {scenario: walk, sensor_count: 2, loop: true}}
  - {name: fusion, type: fusion, params: {method: kalman, trigger: arrival}}
  - {name: robot, type: robot, params: {base: "8,0,8,180"}}
  - {name: separation, type: separation, params: {gesture_stop_s: 3.0}}
YAML
"$SKELGRAPH" launch "$WORK/gesture_stop.yaml" --duration 60 --json >"$WORK/gesture_stop.json" 2>"$WORK/gesture_stop.err" &
gs=$!
wait_for_match "$WORK/gesture_stop.err" "\[start\] separation" 20 || fail "gesture_stop graph did not start"
# Every verdict the monitor publishes, from one reader started before the gesture: the stop lasts only
# gesture_stop_s, and a reader started anew for each look may take longer than that to find the
# monitor on a busy machine.
"$SKELGRAPH" topic echo skelgraph/safety --json >"$WORK/gs_verdicts.jsonl" 2>"$WORK/gs_echo.err" &
gs_echo=$!
wait_for_match "$WORK/gs_echo.err" "echo: matched" 60 || fail "no reader of skelgraph/safety: $(cat "$WORK/gs_echo.err")"
# Until the verdicts show, in this order, each (STATE, text in the reason) of the arguments.
verdicts_show() {
  python3 - "$WORK/gs_verdicts.jsonl" "$@" <<'PY'
import json, sys
want = [tuple(a.split(":", 1)) for a in sys.argv[2:]]
k = 0
for line in open(sys.argv[1]):
    try:
        d = json.loads(line)["data"]
    except (ValueError, KeyError):
        continue  # a line still being written
    if k < len(want) and d["state"] == want[k][0] and want[k][1] in d["reason"]:
        k += 1
sys.exit(0 if k == len(want) else 1)
PY
}
wait_verdicts() { local deadline=$((SECONDS + 60)); until verdicts_show "$@"; do [ "$SECONDS" -lt "$deadline" ] || return 1; sleep 0.2; done; }
wait_verdicts "RUN:" || fail "the monitor never ran with the worker 8 m away: $(tail -2 "$WORK/gs_verdicts.jsonl")"
"$PUBLISH_GESTURE" 1 stop 2>/dev/null || fail "the stop gesture was not published"
wait_verdicts "RUN:" "PROTECTIVE_STOP:stop gesture by person 7" || fail "no stop for the gesture: $(tail -2 "$WORK/gs_verdicts.jsonl")"
wait_verdicts "RUN:" "PROTECTIVE_STOP:stop gesture by person 7" "RUN:" ||
  fail "the robot did not run again after gesture_stop_s: $(tail -2 "$WORK/gs_verdicts.jsonl")"
kill "$gs_echo" 2>/dev/null || true
kill -INT "$gs"
wait "$gs" || fail "gesture_stop launch: $(tail -3 "$WORK/gesture_stop.err")"
json_check "$WORK/gesture_stop.json" '[c for c in d["components"] if c["name"] == "separation"][0]["details"]["stop_gestures"] >= 1 and [c for c in d["components"] if c["name"] == "robot"][0]["details"]["protective_stops"] >= 1'
ok "a stop gesture stops the robot with nobody near, and it runs again after gesture_stop_s"
echo "robot: all checks passed"
