#!/usr/bin/env bash
# A component started over inside a running launch (what `skelgraph launch`
# does when its secure participant is stuck in authentication, Fast DDS 2.9;
# docs/security.md), forced here with `launch --test-auth-stall`
# on the loopback profile: the recorder restarts once with a new participant,
# rejoins the running session, and its first file is kept (the second part
# goes to <label>_<session>_<host>_2.mcap); both parts merge into one session.
source "$(dirname "$0")/lib.sh"

cat >"$WORK/graph.yaml" <<YAML
components:
  - name: sync
    type: sync_master
    params:
      label: restart
  - name: recorder
    type: recorder
    params:
      directory: $WORK/rec
      host: hostA
YAML
"$SKELGRAPH" launch "$WORK/graph.yaml" --test-auth-stall recorder@3 --duration 8 --json \
  >"$WORK/launch.json" 2>"$WORK/launch.err" || fail "launch: $(tail -5 "$WORK/launch.err")"
grep -q "recorder: restarting it with a new DDS participant: 'test' (simulated)" "$WORK/launch.err" ||
  fail "no restart: $(cat "$WORK/launch.err")"
[ "$(grep -c "restarting it" "$WORK/launch.err")" -eq 1 ] || fail "restarted more than once: $(cat "$WORK/launch.err")"
json_check "$WORK/launch.json" 'all(c["state"] == "OK" for c in d["components"])'
ls "$WORK/rec" >"$WORK/files.txt"
[ "$(grep -c '^restart_[0-9]*_hostA\(_2\)\?\.mcap$' "$WORK/files.txt")" -eq 2 ] || fail "expected two parts: $(cat "$WORK/files.txt")"
for f in "$WORK"/rec/*.mcap; do
  "$SKELGRAPH" bag info "$f" --json >"$WORK/info.json"
  json_check "$WORK/info.json" 'd["valid"] and d["ticks_acked_by_host"].get("hostA", 0) >= 30'
done
"$SKELGRAPH" bag merge "$WORK"/rec/*.mcap --out "$WORK/merged.mcap" >/dev/null
"$SKELGRAPH" bag info "$WORK/merged.mcap" --json >"$WORK/merged.json"
json_check "$WORK/merged.json" 'len(d["sessions"]) == 1 and d["ticks_acked_by_host"]["hostA"] >= 150'
ok "restart: the recorder started over once with a new participant; both parts kept ($(tr '\n' ' ' <"$WORK/files.txt")), $(json_get "$WORK/merged.json" 'd["ticks_acked_by_host"]["hostA"]') ticks acked in the merged session"
