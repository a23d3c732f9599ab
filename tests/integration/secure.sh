#!/usr/bin/env bash
# The secure profile on three hosts (network namespaces, netns_cell.sh):
# credentials from `skelgraph security init` (a master, two sensor hosts, a
# read-only host), the cell working end to end; strangers shut out: no
# credentials, or a certificate of another CA, can neither read skeletons nor
# start a recording; the read-only host reads fused skeletons but cannot
# publish sync commands; the robot (host `arm`) obeys a stop from the
# robot-control host only: neither a stranger nor the read-only host can make
# it stop; on the wire (tshark) no topic name, type name or other plaintext
# of our data.
#
#   secure.sh SKELGRAPH LOSSY_LINK
source "$(dirname "$0")/lib.sh"
LOSSY=${2:?usage: $0 skelgraph lossy_link}
CELL_PROFILE=secure
source "$(dirname "$0")/netns_cell.sh"
if ! netns_available; then
  echo "SKIP: this kernel or user may not create network namespaces (ip netns add failed): the LAN tests need them"
  exit 77
fi
cell_up "$LOSSY"
"$SKELGRAPH" security init "$WORK/creds" --master fusion --sensors sensor1,sensor2 --readers reader1 \
  --robots arm --robot-control fusion --json >"$WORK/init.json"
json_check "$WORK/init.json" 'd["hosts"]["reader1"]["role"] == "reader" and "*" in d["hosts"]["fusion"]["publishes"] and d["hosts"]["fusion"]["roles"] == ["master", "robot-control"] and d["hosts"]["fusion"]["denied"] == ["skelgraph/robot/state"] and d["hosts"]["arm"]["publishes"][0] == "skelgraph/robot/state"'
"$SKELGRAPH" security check "$WORK/creds" --json >"$WORK/check.json" || fail "security check: $(cat "$WORK/check.json")"
"$SKELGRAPH" security init "$WORK/other" --master fusion --sensors sensor1,sensor2 >/dev/null  # another cell's CA
CELL_DDS_ARGS=(--security "$WORK/creds")

spawn sw "$WORK/tshark.out" "$WORK/tshark.err" tshark -i br0 -w "$WORK/cell.pcapng" -q
capture=$SPAWNED
wait_for_match "$WORK/tshark.err" "Capturing on" 10 || fail "tshark did not start: $(cat "$WORK/tshark.err")"
# Hosts one after another (a second apart): participants that discover each other at
# the same moment sometimes never finish authenticating with Fast DDS 2.9 (docs/security.md).
for h in fusion sensor1 sensor2; do
  spawn_sg "$h" "$WORK/$h.json" "$WORK/$h.err" launch "$SRC/bringup/cell.yaml" --host "$h" --duration 300 --json
  eval "p_$h=\$SPAWNED"
  sleep 1
done
# The robot: a host of its own (identity `arm`) in sensor1's namespace.
printf 'components:\n  - {name: robot, type: robot, params: {robot_id: robot1}}\n' >"$WORK/arm.yaml"
SKELGRAPH_HOST=arm spawn_sg sensor1 "$WORK/arm.json" "$WORK/arm.err" launch "$WORK/arm.yaml" --duration 300 --json
p_arm=$SPAWNED
cell_started=$SECONDS

# A new secure participant (each command-line tool run is one) sometimes does not
# match the cell within 30 s, and the next one does within 1-2 s (Fast DDS 2.9's
# authentication; measured and reported in docs/security.md): tools here get 3 tries.
# 1. The cell, authenticated and encrypted, end to end.
# Fused skeletons flow on the secure cell: at least 30 in a 3 s window (30 Hz gives 90;
# the rate on a busy machine is the benchmarks' business), up to 3 windows (a new
# secure participant may take a while to match).
rate() { sg fusion topic hz skelgraph/skeleton/fused --window 3 --json --timeout 15 >"$WORK/hz.json" 2>"$WORK/hz.err" &&
  python3 -c 'import json, sys; sys.exit(0 if json.load(open(sys.argv[1]))["samples"] >= 30 else 1)' "$WORK/hz.json" && json_get "$WORK/hz.json" 'round(d["rate_hz"], 1)' >>"$WORK/rates.txt"; }
retry 3 rate || fail "no fused skeletons on the secure cell in 3 windows: $(cat "$WORK/hz.json" 2>/dev/null) $(cat "$WORK/hz.err")"
r=$(tail -1 "$WORK/rates.txt")
# Both sensor hosts in the fused joints. A sensor host stuck in authentication is
# restarted 10 s after its start, so the fusion host may fuse only one for the
# first ~15 s (a clean-clone run read one at 14 s): up to 4 looks, 5 s apart.
both() {
  sg fusion topic echo skelgraph/skeleton/fused --json --count 20 --timeout 10 >"$WORK/fused.jsonl" 2>>"$WORK/fused.err" &&
    python3 -c '
import json, sys
masks = [max(j["sensor_mask"] for j in json.loads(l)["data"]["joints"]) for l in open(sys.argv[1])]
sys.exit(0 if max(masks) == 3 else 1)' "$WORK/fused.jsonl" && return 0
  sleep 5
  return 1
}
retry 4 both || fail "fused joints not from both sensor hosts after 4 looks: $(grep -h 'authenticat\|restart' "$WORK"/*.err | tail -5)"
# A component whose participant is stuck in authentication is started over by
# launch 10 s after its start (docs/security.md): the session starts once that
# is behind us, so every host records all of it.
while [ $((SECONDS - cell_started)) -lt 15 ]; do sleep 1; done
retry 3 sg fusion sync start --label secure --timeout 10 >/dev/null || fail "sync start on the secure cell"
ok "secure cell: fused $r Hz from both authenticated sensor hosts; sync session started by the master host"

# 2. Strangers on sensor2's host try to read and to start a recording (their own sync master).
stranger() {  # stranger NAME ARGS...: read fused skeletons, then act as sync master for 4 s
  local name=$1; shift
  if on sensor2 "$SKELGRAPH" topic echo skelgraph/skeleton/fused --count 1 --timeout 5 "$@" >"$WORK/$name.read" 2>&1; then
    fail "$name read fused skeletons: $(head -c 300 "$WORK/$name.read")"
  fi
  on sensor2 "$SKELGRAPH" launch "$SRC/bringup/sync.yaml" --duration 4 "$@" >"$WORK/$name.sync" 2>&1 || true
}
stranger nocreds --profile lan --interface "$(addr sensor2)"
stranger otherca --profile secure --security "$WORK/other" --interface "$(addr sensor2)"
grep -q "no sample on skelgraph/skeleton/fused" "$WORK/nocreds.read" || fail "nocreds: $(cat "$WORK/nocreds.read")"
# The read-only host: reads, but may not publish sync commands.
SKELGRAPH_HOST=reader1 retry 3 on sensor2 "$SKELGRAPH" topic echo skelgraph/skeleton/fused --count 5 --json --timeout 10 \
  $(sg_args sensor2) >"$WORK/reader.read" 2>"$WORK/reader.err" || fail "the read-only host could not read: $(cat "$WORK/reader.err")"
if SKELGRAPH_HOST=reader1 on sensor2 "$SKELGRAPH" launch "$SRC/bringup/sync.yaml" --duration 3 $(sg_args sensor2) \
  >"$WORK/reader.sync" 2>&1; then
  fail "the read-only host ran a sync master: $(tail -3 "$WORK/reader.sync")"
fi
grep -q "could not create a writer on skelgraph/sync (security: the permissions do not let host 'reader1' publish it" \
  "$WORK/reader.sync" || fail "reader1's refusal: $(tail -3 "$WORK/reader.sync")"
# The robot's commands: a stranger finds no robot to talk to, the read-only host may not
# write a command, the robot-control host stops it.
if on sensor2 "$SKELGRAPH" robot stop --timeout 3 --profile lan --interface "$(addr sensor2)" >"$WORK/stranger.robot" 2>&1; then
  fail "a stranger's robot stop was taken: $(cat "$WORK/stranger.robot")"
fi
grep -q "no state of a robot" "$WORK/stranger.robot" || fail "stranger: $(tail -2 "$WORK/stranger.robot")"
if SKELGRAPH_HOST=reader1 sg sensor2 robot stop --timeout 5 >"$WORK/reader.robot" 2>&1; then
  fail "the read-only host's robot stop went out: $(cat "$WORK/reader.robot")"
fi
grep -q "could not create a writer on skelgraph/robot/command (security: the permissions do not let host 'reader1'" \
  "$WORK/reader.robot" || fail "reader1's robot stop: $(tail -2 "$WORK/reader.robot")"
retry 3 sg fusion robot stop --timeout 10 --json >"$WORK/control.robot" || fail "the robot-control host's stop was not taken"
json_check "$WORK/control.robot" 'd["taken"] and d["source"] == "operator"'
ok "robot: a stranger and the read-only host cannot stop it; the robot-control host can"
retry 3 sg fusion sync stop --timeout 10 --json >"$WORK/stop.json" || fail "sync stop"
# Every recorder closes its file(s) after the STOP (and its linger): complete files from each host.
closed() { ls "$WORK"/{fusion,sensor1,sensor2}/recordings/secure_*.mcap &&
  "$SKELGRAPH" bag info "$WORK"/{fusion,sensor1,sensor2}/recordings/secure_*.mcap; }
wait_until 15 closed || fail "no complete recording of the session on every host: $(ls -R "$WORK"/*/recordings)"
# Every recorder recorded the master's session only: no session of the strangers'.
ls "$WORK"/{fusion,sensor1,sensor2}/recordings/ >"$WORK/files.txt"
grep -q "^secure_" "$WORK/files.txt" || fail "no secure session recorded: $(cat "$WORK/files.txt")"
if grep -q "^session_" "$WORK/files.txt"; then fail "a recorder obeyed a stranger's START: $(cat "$WORK/files.txt")"; fi
"$SKELGRAPH" bag merge "$WORK"/{fusion,sensor1,sensor2}/recordings/secure_*.mcap --out "$WORK/merged.mcap" >/dev/null
"$SKELGRAPH" bag info "$WORK/merged.mcap" --json >"$WORK/info.json"
# Every tick acked by every host; a recorder that launch started over within the session (a stuck
# authentication, docs/security.md; it goes on in a second file) misses at most the ticks of its
# restart: 2 s of 33 ms ticks (about 1 s on an idle machine; 1.2 s seen beside two busy loops).
ticks=$(json_get "$WORK/stop.json" 'd["tick"]')
restart_ticks=$((2000 / 33))
for h in fusion sensor1 sensor2; do
  files=$(ls "$WORK/$h"/recordings/secure_*.mcap | wc -l)
  acked=$(json_get "$WORK/info.json" 'd["ticks_acked_by_host"].get("'"$h"'", 0)')
  if [ "$files" -eq 1 ]; then
    [ "$acked" -eq "$ticks" ] || fail "$h acked $acked of $ticks ticks"
  else
    grep -q "restarting it with a new DDS participant" "$WORK/$h.err" || fail "$h: $files files but no restart reported"
    [ "$acked" -ge $((ticks - restart_ticks)) ] || fail "$h acked $acked of $ticks ticks across its restart"
    echo "  $h: recorder started over within the session ($files files), $acked of $ticks ticks acked"
  fi
done
ok "no credentials / another CA: read nothing, started no recording; read-only host reads but its sync master is refused"

# 3. The wire: encrypted. No topic or type name (discovery and status data name them in the clear on lan).
kill -INT "$capture"
wait "$capture" || true
frames=$(tshark -r "$WORK/cell.pcapng" 2>/dev/null | wc -l)
[ "$frames" -gt 1000 ] || fail "capture too small: $frames frames"
secure=$(tshark -r "$WORK/cell.pcapng" -Y "rtps.sm.id == 0x31 || rtps.sm.id == 0x33" 2>/dev/null | wc -l)  # SEC_PREFIX, SRTPS_PREFIX
[ "$secure" -gt 100 ] || fail "only $secure packets with protected RTPS submessages"
topics=$(tshark -r "$WORK/cell.pcapng" -Y rtps.param.topicName -T fields -e rtps.param.topicName 2>/dev/null | grep -c . || true)
[ "$topics" -eq 0 ] || fail "$topics topic names in clear discovery data"
# In the clear by design of DDS Security: certificates (host names) and the signed permissions
# document (its <topic> rules) in the authentication handshake, participant names in SPDP.
# Not: topic names anywhere else (discovery, status data), type names, frame ids of skeletons ("world").
plain=$(python3 -c '
import re, sys
data = open(sys.argv[1], "rb").read()
print(len(re.findall(rb"(?<!<topic>)skelgraph/", data)) + data.count(b"skelgraph::msg") + data.count(b"world"))' "$WORK/cell.pcapng")
[ "$plain" -eq 0 ] || fail "$plain plaintext topic names, type names or skeleton frame ids in the capture"
ok "tshark: $frames frames, $secure with protected RTPS submessages, no topic/type name or skeleton data in the clear"

kill -INT "$p_arm"
wait "$p_arm" || fail "the robot did not stop cleanly: $(tail -3 "$WORK/arm.err")"
# What the robot took: one protective stop, every command from the operator on the robot-control host.
json_check "$WORK/arm.json" '[c for c in d["components"] if c["name"] == "robot"][0]["details"]["protective_stops"] == 1 and [c for c in d["components"] if c["name"] == "robot"][0]["details"]["refused_source"] == 0 and [c for c in d["components"] if c["name"] == "robot"][0]["details"]["stopped"]'
for h in fusion sensor1 sensor2; do eval "kill -INT \$p_$h"; done
for h in fusion sensor1 sensor2; do eval "wait \$p_$h" || fail "$h did not stop cleanly: $(tail -3 "$WORK/$h.err")"; done
echo "secure: all checks passed"
