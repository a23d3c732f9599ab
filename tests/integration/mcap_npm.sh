#!/usr/bin/env bash
# MCAP both ways between skelgraph and the reference TypeScript library
# (@mcap/core, what Lichtblick/Foxglove read with):
# 1. Our files as the viewers read them: @mcap/core validates and indexes them,
#    the omgidl packages decode every message to the values written and
#    re-encode it to the same bytes (tests/npm/check_mcap.mjs). Every
#    compression; every wire type.
# 2. Every file the reference writer writes (tests/npm/mcap_matrix.mjs: each
#    combination of its options, uncompressed, lz4, zstd) read by
#    `skelgraph bag info` as valid with its messages, topic, metadata and
#    attachment; and one of our recordings rewritten in every layout reads,
#    evaluates and exports the same as the original.
set -euo pipefail
SAMPLES=${1:?usage: $0 write_mcap_samples NPM_DIR SKELGRAPH}
NPM_DIR=${2:?}
SKELGRAPH=${3:?}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# The scripts are run from the install directory, next to their packages.
cp "$(dirname "$0")"/../npm/*.mjs "$NPM_DIR/"
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

# The writer's option matrix.
node "$NPM_DIR/mcap_matrix.mjs" "$WORK/matrix" >"$WORK/matrix.json"
# The same content as ours, in every layout.
node "$NPM_DIR/mcap_matrix.mjs" "$WORK/copies" "$WORK/zstd.mcap" >"$WORK/copies.json"
python3 - "$SKELGRAPH" "$WORK" <<'PY'
import json, os, subprocess, sys
skelgraph, work = sys.argv[1:]

def info(files):
    r = subprocess.run([skelgraph, "bag", "info", "--json", *files], capture_output=True, text=True)
    assert r.returncode == 0, f"bag info exit {r.returncode}: {r.stderr[-2000:]}"
    got = json.loads(r.stdout)
    return got if isinstance(got, list) else [got]

def check(expected, got):
    name = f'{os.path.basename(expected["file"])} {expected["compression"]} {expected["options"]}'
    assert got["valid"] and got["problem"] == "", (name, got["problem"])
    assert got["messages"] == expected["messages"], (name, got["messages"])
    assert {t["topic"]: t["count"] for t in got["topics"]} == expected["topics"], (name, got["topics"])
    assert len(got["metadata"]) == expected["metadata"], (name, got["metadata"])
    assert got["attachments"] == expected["attachments"], (name, got["attachments"])
    return got

matrix = json.load(open(f"{work}/matrix.json"))
assert len(matrix) > 500, len(matrix)  # 2^9 option sets, chunked ones three times, repeats dropped
results = info([m["file"] for m in matrix])
assert len(results) == len(matrix)
notes = 0
for m, got in zip(matrix, results):
    check(m, got)
    o = m["options"]
    # What is missing is said, as information.
    if o["useChunks"] and not o["useChunkIndex"]:
        assert any("chunk index" in n for n in got["notes"]), got["notes"]
    notes += len(got["notes"])
print(f"ok: {len(matrix)} files of the reference writer's option matrix valid, "
      f"10 messages, 1 metadata, 1 attachment each; {notes} notes on missing indexes")

copies = json.load(open(f"{work}/copies.json"))
original = info([f"{work}/zstd.mcap"])[0]
def export(path, out):
    r = subprocess.run([skelgraph, "bag", "export", path, "--out", out, "--format", "generic"],
                       capture_output=True, text=True)
    assert r.returncode == 0, f"bag export {path}: {r.stderr[-2000:]}"
    return sorted(os.listdir(out))
def evaluate(path):
    r = subprocess.run([skelgraph, "eval", "recording", path, "--json"], capture_output=True, text=True)
    assert r.returncode == 0, f"eval recording {path}: {r.stderr[-2000:]}"
    got = json.loads(r.stdout)
    got.pop("file")
    return got
want = export(f"{work}/zstd.mcap", f"{work}/export_original")
scores = evaluate(f"{work}/zstd.mcap")
assert want, "the original exported nothing"
for c, got in zip(copies, info([c["file"] for c in copies])):
    check(c, got)
    assert got["ticks"] == original["ticks"] and got["sessions"] == original["sessions"], got
    assert got["skeletons_per_sensor"] == original["skeletons_per_sensor"], got["skeletons_per_sensor"]
    assert evaluate(c["file"]) == scores, c["file"]
    out = c["file"] + ".export"
    assert export(c["file"], out) == want, c["file"]
    for name in want:  # identical but for the line naming the source file
        a, b = (open(f"{d}/{name}").read().splitlines() for d in (f"{work}/export_original", out))
        assert len(a) == len(b) > 1 and a[0] == b[0] and a[2:] == b[2:] and b[1].startswith("# source:"), (out, name)
print(f"ok: our recording rewritten in {len(copies)} layouts: same topics, counts, ticks, sessions, "
      f"identical evaluations and exports ({len(want)} files each)")
PY
echo "mcap_npm: all checks passed"
