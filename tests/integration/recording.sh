#!/usr/bin/env bash
# Recording end to end: two recorders playing two hosts (one with its clock
# 250 ms ahead) record a simulated session; the sync master estimates the
# offset; the merge puts both on its timeline with every tick acked by both;
# a replayed recording re-records with identical counts; a recorder killed
# with SIGKILL is recovered with about a second lost (it flushes every second).
source "$(dirname "$0")/lib.sh"

"$SKELGRAPH" launch "$SRC/bringup/sim_dual.yaml" --duration 60 >/dev/null 2>"$WORK/sim.err" &
sim=$!
"$SKELGRAPH" bag record --dir "$WORK/rec" --host hostA --duration 40 --json >"$WORK/a.json" 2>"$WORK/a.err" &
a=$!
"$SKELGRAPH" bag record --clock-offset-ms 250 --dir "$WORK/rec" --host hostB --duration 40 --json >"$WORK/b.json" 2>"$WORK/b.err" &
b=$!
"$SKELGRAPH" run sync_master -p autostart=false --name sync --duration 40 --json >"$WORK/sync.json" 2>"$WORK/sync.err" &
sync=$!
# Both recorders (and the sync master) must have found each other before the session starts.
for _ in $(seq 100); do
  "$SKELGRAPH" topic list --json >"$WORK/topics.json" 2>/dev/null || true
  python3 - "$WORK/topics.json" <<'PY' && break
import json, sys
t = {x["name"]: x for x in json.load(open(sys.argv[1]))}
ok = (t.get("skelgraph/sync", {}).get("readers", 0) >= 2 and t.get("skelgraph/sync_ack", {}).get("readers", 0) >= 3
      and t.get("skelgraph/sync/control", {}).get("readers", 0) >= 1)
sys.exit(0 if ok else 1)
PY
  sleep 0.2
done
"$SKELGRAPH" sync start --label two_hosts --timeout 20 >/dev/null 2>"$WORK/start.err" || fail "sync start: $(cat "$WORK/start.err"); master: $(tail -5 "$WORK/sync.err")"
# A session of about 6 s: while 170 ticks go by (the master ticks at 30 Hz).
"$SKELGRAPH" topic echo skelgraph/sync --count 170 --timeout 30 >/dev/null 2>"$WORK/ticks.err" || fail "ticks: $(cat "$WORK/ticks.err")"
"$SKELGRAPH" sync stop --timeout 20 >/dev/null
kill -INT "$a" "$b" "$sync"
wait "$a" || fail "recorder A: $(cat "$WORK/a.err")"
wait "$b" || fail "recorder B: $(cat "$WORK/b.err")"
wait "$sync" || fail "sync master: $(cat "$WORK/sync.err")"
ticks=$(json_get "$WORK/sync.json" 'd["components"][0]["details"]["ticks_sent"]')
[ "$ticks" -gt 150 ] || fail "only $ticks ticks sent"
ls "$WORK/rec"/two_hosts_*_hostA.mcap "$WORK/rec"/two_hosts_*_hostB.mcap >/dev/null || fail "files: $(ls "$WORK/rec")"
"$SKELGRAPH" bag merge "$WORK/rec"/two_hosts_*.mcap --out "$WORK/merged.mcap" --json >"$WORK/merge.json"
"$SKELGRAPH" bag info "$WORK/merged.mcap" --json >"$WORK/info.json"
python3 - "$WORK/merge.json" "$WORK/info.json" "$ticks" <<'PY' || fail "merge: $(cat "$WORK/merge.json")"
import json, sys
merge, info, ticks = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), int(sys.argv[3])
assert info["valid"], info["problem"]
acks = info["ticks_acked_by_host"]
assert acks.get("hostA") == ticks and acks.get("hostB") == ticks, (acks, ticks)   # every tick, both hosts
assert info["ticks"] == ticks, (info["ticks"], ticks)
off = {v["host"]: v["offset_ns"] for v in merge["inputs"].values()}
assert abs(off["hostB"] - 250e6) < 2e6 and abs(off["hostA"]) < 2e6, off           # the skew, found
assert merge["duplicates_dropped"] > 100, merge                                     # both recorded the same samples
per = info["skeletons_per_sensor"]
assert per["skelgraph/skeleton/raw sensor1"] > 150 and per["skelgraph/skeleton/raw sensor2"] > 150, per
# Frames associated by tick: a record per tick, each sensor's frame at most ticks.
assert merge["tick_records"] == ticks and info["tick_records"] == ticks, (merge["tick_records"], info["tick_records"], ticks)
at = info["ticks_with_frames_of"]
for s in ("sensor1", "sensor2"):
    assert at.get("skelgraph/skeleton/raw " + s, 0) >= 0.5 * ticks, at
assert any(k.startswith("skelgraph/skeleton/truth") and v >= 0.9 * ticks for k, v in at.items()), at   # truth never stops
print("ticks %d acked by both hosts; offsets %s; frames at ticks %s" % (ticks, {h: "%.3f ms" % (o / 1e6) for h, o in off.items()}, at))
PY
ok "two hosts: every tick acked by both, offset of hostB found, merged onto one timeline"
# Fused offline on the merged session's own sync ticks, as the live component would.
"$SKELGRAPH" eval recording "$WORK/merged.mcap" --methods avg,kalman --json >"$WORK/eval.json" || fail "eval of the merged recording"
json_check "$WORK/eval.json" 'd["on_sync_ticks"] and d["ticks"] == '"$ticks"' and d["has_truth"]'
ok "merged recording fused on its $ticks sync ticks: kalman $(json_get "$WORK/eval.json" 'round([s for s in d["streams"] if s["stream"] == "kalman"][0]["mean_error_cm"], 1)') cm"

# A recording replayed and recorded again: the same count on every topic.
a_file=$(ls "$WORK/rec"/two_hosts_*_hostA.mcap)
kill -INT "$sim"; wait "$sim" || true
"$SKELGRAPH" bag record --now --label replay --dir "$WORK/replay" --duration 40 >/dev/null 2>"$WORK/r.err" &
rec=$!
wait_for_match "$WORK/r.err" "recording session" 20 || fail "re-recorder did not start: $(cat "$WORK/r.err")"
timeout 60 "$SKELGRAPH" bag play "$a_file" --json >"$WORK/play.json" 2>"$WORK/play.err" || fail "play (ends by itself at the end of the file): $(cat "$WORK/play.err")"
# The player ended once its reliable readers acknowledged everything; the
# recorder takes what its readers hold before it closes the file on SIGINT.
kill -INT "$rec"; wait "$rec" || fail "re-record: $(cat "$WORK/r.err")"
"$SKELGRAPH" bag info "$a_file" --json >"$WORK/orig.json"
"$SKELGRAPH" bag info "$WORK/replay"/replay_*.mcap --json >"$WORK/again.json"
python3 - "$WORK/orig.json" "$WORK/again.json" "$WORK/play.json" <<'PY' || fail "replay counts differ"
import json, sys
orig, again, play = (json.load(open(p)) for p in sys.argv[1:4])
count = lambda d: {t["topic"]: t["count"] for t in d["topics"]}
o, a = count(orig), count(again)
details = play["components"][0]["details"]
published = details["published"]
assert details["passes"] == 1 and published == details["messages"], details   # the player got to the end
# Reliable topics: every message, exactly. skeleton/raw is best-effort by design
# (a late sample is worthless to fusion), so a loaded machine may drop some:
# most must arrive, and the loss is reported.
for topic in ("skelgraph/skeleton/truth", "skelgraph/sync", "skelgraph/sync/clock"):
    assert o[topic] == a[topic], (topic, o[topic], a[topic])
raw_o, raw_a = o["skelgraph/skeleton/raw"], a["skelgraph/skeleton/raw"]
assert 0.85 * raw_o <= raw_a <= raw_o, (raw_o, raw_a)
print("replayed %d messages; truth %d, sync %d identical; best-effort raw %d of %d" % (published, a["skelgraph/skeleton/truth"], a["skelgraph/sync"], raw_a, raw_o))
PY
ok "replay re-recorded: reliable topics identical"

# SIGKILL: about a second lost (more on a busy machine), everything before it recovered.
"$SKELGRAPH" launch "$SRC/bringup/sim_dual.yaml" --duration 40 >/dev/null 2>&1 &
sim=$!
"$SKELGRAPH" bag record --now --label killed --dir "$WORK/kill" --compression lz4 >/dev/null 2>"$WORK/k.err" &
rec=$!
wait_for_match "$WORK/k.err" "recording session" 20 || fail "recorder did not start: $(cat "$WORK/k.err")"
# About 5 s of the two sensors' skeletons (60 a second) recorded, then the kill.
"$SKELGRAPH" topic echo skelgraph/skeleton/raw --count 300 --timeout 30 >/dev/null 2>&1 || fail "no raw skeletons to record"
killed_ns=$(date +%s%N)  # taken just before the kill (a python start after it adds a busy machine's delay)
kill -9 "$rec"
wait "$rec" 2>/dev/null || true

# A full disk (a small tmpfs in a private mount namespace): already full at
# START, the reason is on the status and the exit code is 1; filling up while
# recording, the same, and what was flushed before is recoverable.
mkdir -p "$WORK/full"
unshare -m -- bash -s "$SKELGRAPH" "$WORK" <<'FULL' || fail "full disk: $(cat "$WORK"/full_*.err 2>/dev/null | tail -5)"
set -euo pipefail
sg=$1 work=$2 disk=$2/full
mount -t tmpfs -o size=64k tmpfs "$disk"
dd if=/dev/zero of="$disk/fill" bs=4k 2>/dev/null || true
set +e
"$sg" bag record --now --dir "$disk/rec" --duration 1 --json >"$work/full_start.json" 2>"$work/full_start.err"; rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "full at START: exit $rc, expected 1" >&2; exit 1; }
umount "$disk"
mount -t tmpfs -o size=200k tmpfs "$disk"   # one or two one-second chunks fit
set +e
"$sg" bag record --now --dir "$disk/rec" --compression none --duration 6 --json >"$work/full_run.json" 2>"$work/full_run.err"; rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "filling up: exit $rc, expected 1" >&2; exit 1; }
"$sg" bag recover "$disk"/rec/*.mcap --out "$work/full_fixed.mcap" --json >"$work/full_recover.json"
umount "$disk"
FULL
python3 - "$WORK/full_start.json" "$WORK/full_run.json" "$WORK/full_recover.json" <<'PY' || fail "full disk: $(cat "$WORK/full_run.json")"
import json, sys
start, run, rec = (json.load(open(p)) for p in sys.argv[1:4])
for d in (start, run):
    c = d["components"][0]
    assert c["state"] == "ERROR" and "No space left on device" in c["message"], c["message"]
assert "cannot record session" in start["components"][0]["message"], start["components"][0]["message"]
assert "recording stopped" in run["components"][0]["message"] and "bag recover" in run["components"][0]["message"]
assert rec["messages"] > 0, rec
print("full at START: %s\nfull while recording: %s; %d messages recovered" % (start["components"][0]["message"], run["components"][0]["message"], rec["messages"]))
PY
ok "full disk: a clear error on the status at START and while recording, no crash, flushed data recoverable"
kill -INT "$sim"; wait "$sim" || true
broken=$(ls "$WORK/kill"/killed_*.mcap)
set +e
"$SKELGRAPH" bag info "$broken" >/dev/null 2>&1; rc=$?
set -e
[ "$rc" -ne 0 ] || fail "a killed recording should not read as complete"
"$SKELGRAPH" bag recover "$broken" --out "$WORK/fixed.mcap" --json >"$WORK/recover.json"
"$SKELGRAPH" bag info "$WORK/fixed.mcap" --json >"$WORK/fixed.json"
python3 - "$WORK/fixed.json" "$killed_ns" <<'PY' || fail "recovery: $(cat "$WORK/recover.json")"
import json, sys
info, killed = json.load(open(sys.argv[1])), int(sys.argv[2])
assert info["valid"], info["problem"]
lost = (killed - info["end_ns"]) / 1e9
# Flushed every second; what a busy machine adds to that (1.8 s seen with two busy loops beside the suite).
assert lost <= 2.5, "lost %.2f s" % lost
raw = {t["topic"]: t["count"] for t in info["topics"]}["skelgraph/skeleton/raw"]
assert raw > 150, raw
print("recovered %d messages; the last %.2f s before the kill lost" % (info["messages"], lost))
PY
ok "SIGKILLed recorder recovered: $(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["messages"], "messages")' "$WORK/fixed.json")"
# An unwritable directory: the reason on the status, exit 1, no crash.
set +e
"$SKELGRAPH" bag record --now --dir /proc/skelgraph-cannot-write --duration 1 --json >"$WORK/unwritable.json" 2>/dev/null
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "unwritable directory: exit $rc, expected 1"
json_check "$WORK/unwritable.json" '"cannot create recording directory /proc/skelgraph-cannot-write" in d["components"][0]["details"]["error"]'
ok "unwritable directory: $(json_get "$WORK/unwritable.json" 'd["components"][0]["details"]["error"]')"
echo "recording: all checks passed"
