#!/usr/bin/env bash
# What DDS Security costs: skeletons from one host to another (network
# namespaces, tests/integration/netns_cell.sh) on the `lan` profile and on
# `secure` (authenticated, access-controlled, AES-GCM encrypted), same load:
# 4 skeleton streams at 30 Hz from sensor1 to the fusion host for SECONDS.
# Per profile: latency (median, p99, max), samples lost, and the CPU time of
# the publishing and the receiving process. JSON on stdout.
#   bench/secure_bench.sh BUILD_DIR [SECONDS]
set -euo pipefail
build=$(cd "${1:?usage: secure_bench.sh BUILD_DIR [SECONDS]}" && pwd)
seconds=${2:-30}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export SKELGRAPH_SOURCE_DIR=$root SKELGRAPH_DOMAIN=79
set -- "$build/bin/skelgraph"
source "$root/tests/integration/lib.sh"
source "$root/tests/integration/netns_cell.sh"
netns_available || fail "secure_bench needs network namespaces (root)"
cell_up "$build/tests/lossy_link"
"$SKELGRAPH" security init "$WORK/creds" --master fusion --sensors sensor1 >/dev/null

run() {  # run PROFILE: the load on PROFILE; results in $WORK/PROFILE.{pub,recv}.json
  local profile=$1 args=()
  [ "$profile" = secure ] && args=(SKELGRAPH_SECURITY_DIR="$WORK/creds")
  env "${args[@]}" SKELGRAPH_PROFILE="$profile" SKELGRAPH_INTERFACES="$(addr fusion)" \
    bash -c "$(declare -f on); NS=$NS WORK=$WORK; on fusion \"$build/bench/stream_receive\" $((seconds + 8)) skeleton" \
    >"$WORK/$profile.recv.json" &
  local r=$!
  env "${args[@]}" SKELGRAPH_PROFILE="$profile" SKELGRAPH_INTERFACES="$(addr sensor1)" \
    bash -c "$(declare -f on); NS=$NS WORK=$WORK; on sensor1 \"$build/bench/publish_streams\" 4 0 $seconds" \
    >"$WORK/$profile.pub.json"
  wait "$r"
}
run lan
run secure
python3 - "$WORK" "$seconds" <<'PY'
import json, sys
w, seconds = sys.argv[1], float(sys.argv[2])
out = {"load": "4 skeleton streams at 30 Hz, sensor1 -> fusion host over a veth/TAP bridge", "seconds": seconds}
for p in ("lan", "secure"):
    pub, recv = json.load(open(f"{w}/{p}.pub.json")), json.load(open(f"{w}/{p}.recv.json"))
    s = recv["streams"]
    med = sorted(v["latency_ms_median"] for v in s.values())
    out[p] = {"published": pub["skeleton_raw"], "received": sum(v["received"] for v in s.values()),
              "missing": sum(v["missing"] for v in s.values()),
              "latency_ms_median": med[len(med) // 2] if med else None,
              "latency_ms_p99": max((v["latency_ms_p99"] for v in s.values()), default=None),
              "latency_ms_max": max((v["latency_ms_max"] for v in s.values()), default=None),
              "cpu_s_publisher": pub["cpu_s"], "cpu_s_receiver": recv["cpu_s"]}
l, s = out["lan"], out["secure"]
out["secure_vs_lan"] = {"latency_median_ms_added": s["latency_ms_median"] - l["latency_ms_median"],
                        "cpu_publisher_ratio": s["cpu_s_publisher"] / l["cpu_s_publisher"],
                        "cpu_receiver_ratio": s["cpu_s_receiver"] / l["cpu_s_receiver"]}
print(json.dumps(out, indent=2))
PY
