#!/usr/bin/env bash
# Another vendor's DDS on our graph (docs/interop.md): a Cyclone DDS 0.10 peer
# (tests/support/cyclone_peer.c, our IDL compiled by Cyclone's idlc) on loopback.
#  1. loopback-interop: it reads our skeletons and sync ticks;
#  2. as a sync master it starts a session that our recorder obeys (file, acks);
#  3. pinned: on the plain loopback profile (TypeInformation announced) Cyclone
#     rejects our endpoints' discovery data and reads nothing. When this check
#     fails, one side changed: revisit the *-interop profiles and the docs.
#
#   cyclone_interop.sh SKELGRAPH CYCLONE_PEER
source "$(dirname "$0")/lib.sh"
PEER=${2:?usage: $0 skelgraph cyclone_peer}
cat >"$WORK/cyclone.xml" <<'XML'
<CycloneDDS><Domain id="any">
  <General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>31</MaxAutoParticipantIndex>
    <Peers><Peer address="127.0.0.1"/></Peers></Discovery>
</Domain></CycloneDDS>
XML
export CYCLONEDDS_URI="file://$WORK/cyclone.xml"

# graph PROFILE: a simulated cell and a sync master, 7 s; returns once both have started.
graph() {
  "$SKELGRAPH" run sim --name cell --profile "$1" --duration 7 >/dev/null 2>"$WORK/sim_$1.err" &
  "$SKELGRAPH" launch "$SRC/bringup/sync.yaml" --profile "$1" --duration 7 >/dev/null 2>"$WORK/sync_$1.err" &
  wait_for_match "$WORK/sim_$1.err" "^\[start\] cell" 10 || fail "the simulator did not start: $(cat "$WORK/sim_$1.err")"
  wait_for_match "$WORK/sync_$1.err" "^\[start\]" 10 || fail "the sync master did not start: $(cat "$WORK/sync_$1.err")"
}

# 1. Fast DDS -> Cyclone: the peer reads for 5 s from the graph's start.
graph loopback-interop
"$PEER" sub 5 >"$WORK/sub.json" 2>"$WORK/sub.err" || fail "cyclone sub: $(cat "$WORK/sub.err")"
# Raw skeletons are in the sensor's frame and the sensors are 1.2 m above the
# floor: a decoded head lies between -1.2 m (the floor) and 1.5 m. (0.3 was too
# tight: a clean-clone run decoded a first head at 0.17 m.)
json_check "$WORK/sub.json" 'd["skeletons"] > 100 and d["first_sensor"] in ("sensor1", "sensor2") and -1.2 < d["first_head_y"] < 1.5 and d["sync"]["tick"] > 90'
ok "Cyclone read $(json_get "$WORK/sub.json" 'd["skeletons"]') skeletons and $(json_get "$WORK/sub.json" 'd["sync"]["tick"]') sync ticks from our graph (loopback-interop)"
wait

# 2. Cyclone -> Fast DDS: a Cyclone sync master, our recorder.
"$SKELGRAPH" bag record --dir "$WORK/rec" --host fast --profile loopback-interop --duration 8 --json \
  >"$WORK/rec.json" 2>"$WORK/rec.err" &
rec=$!
wait_for_match "$WORK/rec.err" "^\[start\] recorder" 10 || fail "the recorder did not start: $(cat "$WORK/rec.err")"
"$PEER" sync cyclone_session 4242 >"$WORK/sync.json" 2>"$WORK/sync.err" || fail "cyclone sync: $(cat "$WORK/sync.err")"
wait "$rec" || fail "recorder: $(tail -3 "$WORK/rec.err")"
[ -f "$WORK/rec/cyclone_session_4242_fast.mcap" ] || fail "no recording of the Cyclone session: $(ls "$WORK/rec")"
"$SKELGRAPH" bag info "$WORK/rec/cyclone_session_4242_fast.mcap" --json >"$WORK/info.json"
json_check "$WORK/info.json" 'd["valid"] and d["ticks_acked_by_host"]["fast"] == 30'
ok "a Cyclone sync master's START/30 TICKs/STOP: our recorder wrote the session and acked every tick"

# 3. Pinned: the plain loopback profile announces TypeInformation, which Cyclone 0.10 rejects.
graph loopback
"$PEER" sub 4 >"$WORK/sub0.json" 2>"$WORK/sub0.err" || fail "cyclone sub: $(cat "$WORK/sub0.err")"
json_check "$WORK/sub0.json" 'd["skeletons"] == 0 and d["sync"]["tick"] == 0'
grep -q "TYPE_INFORMATION) invalid" "$WORK/sub0.err" ||
  fail "Cyclone no longer says why it ignores us: $(head -c 300 "$WORK/sub0.err")"
wait
ok "pinned: with TypeInformation announced (loopback) Cyclone rejects our endpoints and reads nothing"
echo "cyclone_interop: all checks passed"
