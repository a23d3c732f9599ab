#!/usr/bin/env bash
# The README's test command on a busy machine: a fresh clone of this
# repository is built once, then `tools/run test` runs N times (default 3),
# each with two CPU-bound busy loops beside it (killed after the run). Prints
# one line per run: exit code, wall time, ctest's summary. Logs in OUT_DIR.
#   bench/loaded_suite.sh [RUNS] [OUT_DIR]
set -u
runs=${1:-3}
out=${2:-/tmp/skelgraph-loaded}
src=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
clone="$out/clone"
# The tests read the shared data sets beside the repository (../shared/data).
if [ -d "$src/../shared" ] && [ ! -e "$out/shared" ]; then ln -s "$(cd "$src/../shared" && pwd)" "$out/shared"; fi
rm -rf "$clone" && git clone -q "$src" "$clone" && cd "$clone" || exit 1
echo "commit $(git rev-parse --short HEAD)"
start=$(date +%s)
tools/run test -R '^test_registry$' >"$out/build.log" 2>&1
echo "build: rc=$? $(($(date +%s) - start)) s"
for i in $(seq "$runs"); do
  (while :; do :; done) & h1=$!
  (while :; do :; done) & h2=$!
  start=$(date +%s)
  tools/run test >"$out/run$i.log" 2>&1
  rc=$?
  kill "$h1" "$h2"
  echo "run $i (two busy loops beside it): rc=$rc, $(($(date +%s) - start)) s; $(grep -E 'tests passed|Total Test time' "$out/run$i.log" | tr '\n' ' ')"
done
