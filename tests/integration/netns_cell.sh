# A LAN of three hosts in network namespaces, for the multi-host tests
# (sourced after lib.sh). Hosts `fusion` (10.231.0.1), `sensor1` (.2) and
# `sensor2` (.3) hang on a bridge in a fourth namespace (the switch); sensor1's
# cable is tests/support/lossy_link (TAP devices), so a test can add loss and
# delay or pull it (`link loss 0.1`, `link delay 20`, `link down`) on any
# kernel, sch_netem or not. Every host has its own /dev/shm (as separate
# machines do), so nothing passes between hosts but through the network.
# Namespaces are named after this script's pid and removed on exit.
#
#   cell_up LOSSY_LINK       make the namespaces
#   on HOST CMD...           run CMD in HOST (cwd $WORK/HOST, its own /dev/shm, SKELGRAPH_HOST=HOST unless set)
#   sg HOST ARGS...          skelgraph ARGS in HOST on the cell's profile ($CELL_PROFILE, default lan)
#   spawn_sg HOST OUT ERR ARGS...   the same in the background, pid in SPAWNED
#   spawn HOST OUT ERR CMD...       any command in HOST in the background, pid in SPAWNED
#   link CMD                 a command to sensor1's cable
#   link_stats FILE          its frame counts so far (JSON; see tests/support/lossy_link.cpp)
#   addr HOST                the host's address

NS=sg$$_
SUBNET=10.231.0
CELL_PROFILE=${CELL_PROFILE:-lan}
CELL_DDS_ARGS=()  # extra DDS options for every `sg` (e.g. --discovery-server)

netns_available() {
  ip netns add "${NS}probe" 2>/dev/null && ip netns del "${NS}probe"
}

addr() {
  case $1 in
    fusion) echo "$SUBNET.1" ;; sensor1) echo "$SUBNET.2" ;; sensor2) echo "$SUBNET.3" ;;
    *) fail "no host $1" ;;
  esac
}

cell_down() {
  exec 7>&- 2>/dev/null || true
  for h in fusion sensor1 sensor2 sw; do
    for pid in $(ip netns pids "$NS$h" 2>/dev/null); do kill -KILL "$pid" 2>/dev/null || true; done
  done
  [ -n "${LINK_PID:-}" ] && kill "$LINK_PID" 2>/dev/null && wait "$LINK_PID" 2>/dev/null
  for h in fusion sensor1 sensor2 sw; do ip netns del "$NS$h" 2>/dev/null || true; done
}

cell_up() {
  local lossy=$1
  # SKELGRAPH_KEEP_WORK=DIR: keep a copy of the hosts' files (logs, recordings) there.
  trap 'cell_down; kill $(jobs -p) 2>/dev/null || true; [ -n "${SKELGRAPH_KEEP_WORK:-}" ] && cp -r "$WORK" "$SKELGRAPH_KEEP_WORK"; rm -rf "$WORK"' EXIT
  ip netns add "${NS}sw"
  ip -n "${NS}sw" link set lo up
  ip -n "${NS}sw" link add br0 type bridge
  ip -n "${NS}sw" link set br0 up
  mkdir -p "$WORK/sw" "$WORK/shm_sw"
  for h in fusion sensor1 sensor2; do
    ip netns add "$NS$h"
    ip -n "$NS$h" link set lo up
    mkdir -p "$WORK/$h" "$WORK/shm_$h"
  done
  for h in fusion sensor2; do
    ip -n "${NS}sw" link add "p_$h" type veth peer name eth0 netns "$NS$h"
  done
  mkfifo "$WORK/link.cmd"
  "$lossy" "${NS}sensor1" eth0 "${NS}sw" p_sensor1 <"$WORK/link.cmd" >"$WORK/link.out" 2>"$WORK/link.err" &
  LINK_PID=$!
  exec 7>"$WORK/link.cmd"
  wait_for_match "$WORK/link.out" "^ready" 5 || fail "lossy_link: $(cat "$WORK/link.err")"
  for h in fusion sensor1 sensor2; do
    ip -n "${NS}sw" link set "p_$h" master br0 up
    ip -n "$NS$h" addr add "$(addr "$h")/24" dev eth0
    ip -n "$NS$h" link set eth0 up
    ip -n "$NS$h" route add 224.0.0.0/4 dev eth0  # multicast discovery (lan profile)
  done
}

on() {
  local h=$1; shift
  SKELGRAPH_HOST="${SKELGRAPH_HOST:-$h}" ip netns exec "$NS$h" unshare -m bash -c 'mount --bind "$0" /dev/shm && cd "$1" && shift && exec "$@"' \
    "$WORK/shm_$h" "$WORK/$h" "$@"
}
spawn() {
  local h=$1 out=$2 err=$3; shift 3
  : >"$out"  # exists on return: a caller may read it before the background process has opened it
  ( SKELGRAPH_HOST="${SKELGRAPH_HOST:-$h}" exec ip netns exec "$NS$h" unshare -m bash -c 'mount --bind "$0" /dev/shm && cd "$1" && shift && exec "$@"' \
      "$WORK/shm_$h" "$WORK/$h" "$@" >>"$out" 2>>"$err" ) &
  SPAWNED=$!
}
sg_args() { echo --profile "$CELL_PROFILE" --interface "$(addr "$1")" "${CELL_DDS_ARGS[@]}"; }
sg() {
  local h=$1; shift
  on "$h" "$SKELGRAPH" "$@" $(sg_args "$h")
}
# spawn_sg HOST OUT ERR ARGS...: skelgraph ARGS in HOST in the background, as one
# process (its pid in SPAWNED: killing it kills skelgraph), stdout/stderr to OUT/ERR.
spawn_sg() {
  local h=$1 out=$2 err=$3; shift 3
  # shellcheck disable=SC2046
  spawn "$h" "$out" "$err" "$SKELGRAPH" "$@" $(sg_args "$h")
}

link() {
  local before
  before=$(grep -c "^ok" "$WORK/link.out" || true)
  echo "$*" >&7
  wait_for_count "$WORK/link.out" "^ok" $((before + 1)) 15 && return 0
  fail "lossy_link did not take '$*': $(tail -2 "$WORK/link.out")"
}

link_stats() {
  local before
  before=$(grep -c "^{" "$WORK/link.out" || true)
  echo stats >&7
  if wait_for_count "$WORK/link.out" "^{" $((before + 1)) 15; then
    grep "^{" "$WORK/link.out" | tail -1 >"$1"
    return 0
  fi
  fail "lossy_link gave no stats"
}
