#!/usr/bin/env bash
# The main job as a user runs it: `skelgraph demo` evaluates fusion on the
# simulator, writes the report, runs the live graph (sync, monitor, simulated
# cell, fusion) and says what it saw.
source "$(dirname "$0")/lib.sh"

"$SKELGRAPH" demo --duration 4 --json --report "$WORK/report" >"$WORK/demo.json" 2>"$WORK/demo.err" ||
  fail "demo: $(tail -5 "$WORK/demo.err")"
python3 - "$WORK/demo.json" <<'PY' || fail "demo report: $(head -c 3000 "$WORK/demo.json")"
import json, os, sys
d = json.load(open(sys.argv[1]))
assert os.path.getsize(d["report"]) > 10000, d["report"]
html = open(d["report"]).read()
for s in ("walk", "360", "hide", "box", "occ", "sit", "arms"):
    assert "<h2>%s (2 sensors" % s in html, s
c = {x["name"]: x for x in d["components"]}
assert all(x["state"] == "OK" for x in c.values()), {k: (v["state"], v["message"]) for k, v in c.items()}
assert c["fusion"]["details"]["published"] > 60 and c["fusion"]["details"]["tick_steps"] > 60, c["fusion"]["details"]
sess = d["seen"]["sessions"]
assert sess and sess[0]["ticks"] > 90 and sess[0]["saw_stop"], sess
print("report %s; fused %d skeletons on %d ticks" % (d["report"], c["fusion"]["details"]["published"], sess[0]["ticks"]))
PY
ok "demo: report for the seven scenarios, live graph OK, fusion on the sync ticks"
