#!/usr/bin/env bash
# The same components composed two ways with no code change: both in one
# process (`launch`), or one per process (`run`); the monitor sees the same thing.
source "$(dirname "$0")/lib.sh"

check_monitor() {  # check_monitor REPORT.json LABEL
  python3 - "$1" "$2" <<'PY' || fail "monitor report wrong: $(cat "$1")"
import json, sys
d = json.load(open(sys.argv[1]))
mon = [c for c in d["components"] if c["kind"] == "monitor"][0]["details"]
s = [x for x in mon["sessions"] if x["label"] == sys.argv[2]]
assert len(s) == 1, mon
s = s[0]
assert s["saw_start"], s
assert s["ticks"] >= 30 and s["missing_ticks"] == 0, s
assert s["tick_rate_hz"] > 0, s
assert "sync" in mon["status"] or "sync_master" in mon["status"], mon["status"].keys()
PY
}

# One process.
printf 'components:\n  - {name: sync, type: sync_master, params: {label: together}}\n  - {name: monitor, type: monitor}\n' >"$WORK/both.yaml"
"$SKELGRAPH" launch "$WORK/both.yaml" --duration 3 --json >"$WORK/both.json" 2>"$WORK/both.err" ||
  fail "launch failed: $(cat "$WORK/both.err")"
check_monitor "$WORK/both.json" together
ok "sync_master + monitor in one process"

# One per process: the monitor starts first, the master joins it.
"$SKELGRAPH" run monitor --duration 8 --json >"$WORK/mon.json" 2>"$WORK/mon.err" &
mon=$!
"$SKELGRAPH" run sync_master -p label=apart --duration 3 >"$WORK/sync.out" 2>"$WORK/sync.err" ||
  fail "sync_master process failed: $(cat "$WORK/sync.err")"
wait "$mon" || fail "monitor process failed: $(cat "$WORK/mon.err")"
check_monitor "$WORK/mon.json" apart
python3 -c 'import json,sys; m=[c for c in json.load(open(sys.argv[1]))["components"] if c["kind"]=="monitor"][0]["details"]; s=m["sessions"][0]; assert s["saw_stop"], s' "$WORK/mon.json" ||
  fail "monitor in another process did not see STOP"
ok "sync_master and monitor in separate processes"
echo "composition: all checks passed"
