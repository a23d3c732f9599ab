#!/usr/bin/env bash
# Our MCAP files as Lichtblick/Foxglove read them: @mcap/core validates and
# indexes them, the omgidl packages decode every message to the values written
# and re-encode it to the same bytes (tests/npm/check_mcap.mjs). Every
# compression; every wire type.
set -euo pipefail
SAMPLES=${1:?usage: $0 write_mcap_samples NPM_DIR}
NPM_DIR=${2:?}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# The check script is run from the install directory, next to its packages.
cp "$(dirname "$0")/../npm/check_mcap.mjs" "$NPM_DIR/"
for c in none lz4 zstd; do
  "$SAMPLES" "$WORK/$c.mcap" "$WORK/$c.jsonl" "$c"
  node "$NPM_DIR/check_mcap.mjs" "$WORK/$c.mcap" "$WORK/$c.jsonl" >"$WORK/$c.json"
  python3 - "$WORK/$c.json" "$WORK/$c.jsonl" <<'PY'
import json, sys
got = json.load(open(sys.argv[1]))
n = sum(1 for _ in open(sys.argv[2]))
assert got["messages"] == n == got["streamMessages"], (got, n)
assert got["topics"]["skelgraph/skeleton/raw"] > 50 and got["metadata"] == 1, got
PY
  echo "ok: $c: $(cat "$WORK/$c.json")"
done
echo "mcap_npm: all checks passed"
