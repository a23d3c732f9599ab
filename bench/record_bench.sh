#!/usr/bin/env bash
# Recording benchmark: 4 skeleton streams + 2 depth streams (640x480 uint16,
# 30 Hz) for SECONDS (default 60) into the recorder (no compression), in a
# loopback-only network namespace. Reports samples published vs recorded and
# the recorder's sustained write rate against dd writing the same number of
# bytes to the same disk. JSON on stdout (tools/run bench writes it to
# build/bench/record_bench.json).
# Usage: bench/record_bench.sh BUILD_DIR [SECONDS]
set -euo pipefail
build=${1:?usage: record_bench.sh BUILD_DIR [SECONDS]}
seconds=${2:-60}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "$build/bench/record.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$root/tests/netns-lo.sh" bash -s "$build" "$seconds" "$root" "$work" <<'INNER'
set -euo pipefail
build=$1 seconds=$2 root=$3 work=$4
ip link set lo up
export SKELGRAPH_DOMAIN=77
sg="$build/bin/skelgraph"
"$sg" bag record --now --label bench --include-depth --compression none --dir "$work/rec" --json >"$work/rec.json" 2>"$work/rec.err" &
rec=$!
"$build/bench/publish_streams" 4 2 "$seconds" >"$work/pub.json"
sleep 2
kill -INT "$rec"
wait "$rec"
file=$(ls "$work"/rec/bench_*.mcap)
"$sg" bag info "$file" --json >"$work/info.json"
bytes=$(stat -c %s "$file")
mb=$(( (bytes + 1048575) / 1048576 ))
dd_out=$(dd if=/dev/zero of="$work/dd.bin" bs=1M count="$mb" conv=fdatasync 2>&1 | tail -1)
python3 - "$work/pub.json" "$work/info.json" "$work/rec.json" "$bytes" "$dd_out" <<'PY'
import json, re, sys
pub, info, rec = (json.load(open(p)) for p in sys.argv[1:4])
bytes_, dd = int(sys.argv[4]), sys.argv[5]
counts = {t["topic"]: t["count"] for t in info["topics"]}
recorded = {"skeleton_raw": counts.get("skelgraph/skeleton/raw", 0), "depth": counts.get("skelgraph/depth", 0)}
span = info["duration_s"]
m = re.search(r"([\d.]+) s, ([\d.]+) ([kMG]?B)/s", dd)
unit = {"B": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9}
dd_rate = float(m.group(2)) * unit[m.group(3)] if m else None
rec_rate = bytes_ / span if span > 0 else None
print(json.dumps({
    "published": {"skeleton_raw": pub["skeleton_raw"], "depth": pub["depth"]},
    "recorded": recorded,
    "lost": {k: pub[k] - recorded[k] for k in recorded},
    "file_bytes": bytes_, "recording_span_s": span,
    "recorder_write_MB_per_s": rec_rate / 1e6 if rec_rate else None,
    "dd_same_bytes": dd, "dd_MB_per_s": dd_rate / 1e6 if dd_rate else None,
    "recorder_over_dd": (rec_rate / dd_rate) if rec_rate and dd_rate else None,
    "recorder_io": rec["components"][0]["io"],
    "note": "the recorder writes what arrives (2 depth streams at 30 Hz are about 37 MB/s); dd shows what the disk can take",
}, indent=2))
PY
INNER
