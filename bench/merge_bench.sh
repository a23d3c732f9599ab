#!/usr/bin/env bash
# bag merge's memory on large recordings (issue 30: two 1 GB recordings merge
# with a peak RSS of 300 MB or less): two hosts' recordings of SIZE_MB each
# (bench/host_recording: 30 Hz depth that does not compress, skeletons, the
# fused skeletons both recorded, the master's ticks; the second host's clock
# 1.5 s ahead), merged by `skelgraph bag merge`; peak RSS and time from
# /usr/bin/time. Prints JSON; needs about 4 x SIZE_MB of disk in $TMPDIR.
#   bench/merge_bench.sh BUILD_DIR [SIZE_MB]   (default 1024)
set -euo pipefail
BUILD=$(realpath "${1:?usage: merge_bench.sh BUILD_DIR [SIZE_MB]}")
SIZE=${2:-1024}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$BUILD/bench/host_recording" "$WORK/master.mcap" master "$SIZE" --master >&2
"$BUILD/bench/host_recording" "$WORK/b.mcap" hostb "$SIZE" 1500 >&2
/usr/bin/time -f '%M %e' -o "$WORK/time.txt" "$BUILD/bin/skelgraph" bag merge "$WORK/master.mcap" "$WORK/b.mcap" \
  --out "$WORK/merged.mcap" --compression none --json >"$WORK/merge.json"
python3 - "$WORK" "$SIZE" <<'PY'
import json, os, sys
work, size = sys.argv[1], float(sys.argv[2])
rss_kb, seconds = open(f"{work}/time.txt").read().split()
m = json.load(open(f"{work}/merge.json"))
print(json.dumps({
    "input_mb_each": round(os.path.getsize(f"{work}/master.mcap") / 1e6),
    "output_mb": round(os.path.getsize(f"{work}/merged.mcap") / 1e6),
    "peak_rss_mb": round(int(rss_kb) / 1024, 1),
    "seconds": float(seconds),
    "messages": m["messages"], "duplicates_dropped": m["duplicates_dropped"],
    "tick_records": m["tick_records"], "out_of_order": m["out_of_order"],
    "peak_held_messages": m["peak_held_messages"]}, indent=1))
PY
