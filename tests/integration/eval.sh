#!/usr/bin/env bash
# skelgraph eval and its report: the simulator's dual-sensor 360 scored for
# every method, the HTML report and its SVG figures well-formed, bad input a
# clear error.
source "$(dirname "$0")/lib.sh"

"$SKELGRAPH" eval sim --scenarios 360,arms --json --report "$WORK/report" >"$WORK/eval.json"
python3 - "$WORK/eval.json" "$WORK/report" <<'PY' || fail "eval sim: $(head -c 2000 "$WORK/eval.json")"
import json, sys, os, xml.etree.ElementTree as ET
d, rep = json.load(open(sys.argv[1])), sys.argv[2]
sc = {x["scenario"]: {s["stream"]: s for s in x["streams"]} for x in d["scenarios"]}
s = sc["360"]
det = lambda k, g: s[k]["groups"][g]["detection_pct"]
for m in ("avg", "sum"):
    for g in ("Elbows", "Hands"):
        assert det(m, g) > max(det("sensor1", g), det("sensor2", g)), (m, g, det(m, g))
best = min(s["sensor1"]["mean_error_cm"], s["sensor2"]["mean_error_cm"])
assert s["kalman"]["mean_error_cm"] < 0.75 * best, (s["kalman"]["mean_error_cm"], best)
html = open(os.path.join(rep, "report.html")).read()
assert html.count("<svg") == 10 and "<table>" in html, html.count("<svg")   # 5 figures per scenario
svgs = [f for f in os.listdir(rep) if f.endswith(".svg")]
assert len(svgs) == 10, svgs
for f in svgs:
    root = ET.parse(os.path.join(rep, f)).getroot()   # well-formed
    assert root.tag.endswith("svg")
err = ET.parse(os.path.join(rep, "360_error.svg")).getroot()
paths = [p for p in err.iter() if p.tag.endswith("path") and len(p.get("d", "")) > 100]
assert len(paths) == 7, len(paths)   # a line per stream
print("360: kalman %.1f cm vs best single %.1f cm" % (s["kalman"]["mean_error_cm"], best))
PY
ok "eval sim: fusion beats single sensors on 360; report with $(ls "$WORK/report" | wc -l) files"

set +e
"$SKELGRAPH" eval sim --scenarios nosuch >/dev/null 2>"$WORK/bad.err"; rc=$?
set -e
[ "$rc" -eq 2 ] && grep -q "nosuch" "$WORK/bad.err" || fail "unknown scenario: exit $rc, $(cat "$WORK/bad.err")"
echo "not a recording" >"$WORK/x.mcap"
set +e
"$SKELGRAPH" eval recording "$WORK/x.mcap" >/dev/null 2>"$WORK/bad2.err"; rc=$?
set -e
[ "$rc" -eq 2 ] && grep -q "not an MCAP file" "$WORK/bad2.err" || fail "not a recording: exit $rc, $(cat "$WORK/bad2.err")"
ok "bad input: $(head -1 "$WORK/bad.err"); $(head -1 "$WORK/bad2.err")"
echo "eval: all checks passed"
