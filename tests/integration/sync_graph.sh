#!/usr/bin/env bash
# A sync-only graph started with `skelgraph launch`, inspected from other
# processes with `topic list/echo/hz` and driven with `sync start/stop`.
source "$(dirname "$0")/lib.sh"

# No --duration here: the graph lives until the SIGINT at the end, so slow
# steps on a loaded machine cannot outlast it.
"$SKELGRAPH" launch bringup/sync.yaml 2>"$WORK/launch.err" &
launch_pid=$!

# topic list sees the graph (retry: discovery of a just-started process).
has_sync() {
  "$SKELGRAPH" topic list --json --wait 1 >"$WORK/list.json"
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if any(t["name"]=="skelgraph/sync" and t["writers"]>=1 for t in d) else 1)' "$WORK/list.json"
}
retry 10 has_sync || fail "topic list never showed skelgraph/sync: $(cat "$WORK/list.json")"
json_check "$WORK/list.json" '[t["types"] for t in d if t["name"]=="skelgraph/sync"] == [["skelgraph::msg::SyncCommand"]]'
json_check "$WORK/list.json" 'any(t["name"]=="skelgraph/sync/session" and t["types"]==["skelgraph::msg::SyncCommand"] for t in d)'
json_check "$WORK/list.json" 'any(t["name"]=="skelgraph/sync/control" and t["readers"]>=1 for t in d)'
json_check "$WORK/list.json" 'any(t["name"]=="skelgraph/sync" and "sync" in t["participants"] for t in d)'
ok "topic list shows the sync topics with their IDL type names"

"$SKELGRAPH" topic hz skelgraph/sync --window 3 --json >"$WORK/hz.json"
# What topic hz says agrees with itself (the rate on a busy machine is the benchmarks' business):
json_check "$WORK/hz.json" 'd["samples"] >= 80 and d["rate_hz"] > 0'
json_check "$WORK/hz.json" 'd["min_period_s"] <= 1 / d["rate_hz"] <= d["max_period_s"]'
json_check "$WORK/hz.json" 'd["min_period_s"] > 0 and d["max_period_s"] >= d["min_period_s"]'
ok "topic hz: $(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("%.2f Hz over %d samples" % (d["rate_hz"], d["samples"]))' "$WORK/hz.json")"

"$SKELGRAPH" topic echo skelgraph/sync --count 3 --json --timeout 10 >"$WORK/echo.jsonl"
[ "$(wc -l <"$WORK/echo.jsonl")" -eq 3 ] || fail "echo printed $(wc -l <"$WORK/echo.jsonl") lines, expected 3"
python3 - "$WORK/echo.jsonl" <<'PY' || fail "echo output wrong: $(cat "$WORK/echo.jsonl")"
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
ticks = [r["data"]["tick"] for r in rows]
assert all(r["topic"] == "skelgraph/sync" and r["data"]["kind"] == "TICK" for r in rows), rows
assert ticks == list(range(ticks[0], ticks[0] + 3)), ticks
assert all(r["data"]["label"] == "session" for r in rows)
PY
ok "topic echo decodes consecutive TICKs"

"$SKELGRAPH" sync start --label integ --json >"$WORK/start.json"
json_check "$WORK/start.json" 'd["kind"]=="START" and d["label"]=="integ"'
# A late joiner on the session topic learns the running session.
"$SKELGRAPH" topic echo skelgraph/sync/session --count 1 --json --timeout 10 >"$WORK/session.jsonl"
python3 -c 'import json,sys; r=json.loads(open(sys.argv[1]).readline()); s=json.load(open(sys.argv[2])); assert r["data"]["kind"]=="START" and r["data"]["label"]=="integ" and r["data"]["session_id"]==s["session_id"], (r, s)' \
  "$WORK/session.jsonl" "$WORK/start.json" || fail "session topic did not show the new START"
"$SKELGRAPH" sync stop --json >"$WORK/stop.json"
json_check "$WORK/stop.json" 'd["kind"]=="STOP" and d["label"]=="integ" and d["tick"] >= 0'
ok "sync start/stop from another process, confirmed by the master"

# SIGINT stops the launch cleanly (exit 0) and the master publishes STOP first.
"$SKELGRAPH" sync start --label final --json >"$WORK/final.json"
"$SKELGRAPH" topic echo skelgraph/sync/session --json --timeout 15 >"$WORK/stop_seen.jsonl" &
echo_pid=$!
# The echo must have joined (it shows the running session's START) before the
# launch goes away, or it could never learn of the STOP.
wait_for_match "$WORK/stop_seen.jsonl" '"final"' 15 || fail "session echo never showed the START of 'final'"
kill -INT "$launch_pid"
wait "$launch_pid" || fail "launch exited non-zero after SIGINT: $(cat "$WORK/launch.err")"
wait_for_match "$WORK/stop_seen.jsonl" '"STOP"' 10 || fail "no STOP published on SIGINT: $(cat "$WORK/stop_seen.jsonl")"
kill "$echo_pid" 2>/dev/null || true
grep -q '^\[stop\] sync (sync_master) OK' "$WORK/launch.err" || fail "no final status line: $(cat "$WORK/launch.err")"
ok "SIGINT: launch exits 0 with a status line per component, and the master publishes STOP"

# --duration ends a launch by itself, with exit 0.
"$SKELGRAPH" launch bringup/sync.yaml --duration 2 2>"$WORK/launch2.err" || fail "launch --duration failed: $(cat "$WORK/launch2.err")"
grep -q '^\[stop\] sync (sync_master) OK' "$WORK/launch2.err" || fail "no final status line: $(cat "$WORK/launch2.err")"
ok "launch --duration exits 0"
echo "sync_graph: all checks passed"
