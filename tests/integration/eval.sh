#!/usr/bin/env bash
# skelgraph eval and its report: the simulator's dual-sensor 360 scored for
# every method, the HTML report and its SVG figures well-formed, bad input a
# clear error.
source "$(dirname "$0")/lib.sh"

"$SKELGRAPH" eval sim --scenarios 360,arms --json --report "$WORK/report" --csv "$WORK/eval.csv" >"$WORK/eval.json"
"$SKELGRAPH" eval sim --scenarios 360,arms >"$WORK/eval.md" 2>/dev/null
python3 - "$WORK/eval.json" "$WORK/report" "$WORK/eval.csv" "$WORK/eval.md" <<'PY' || fail "eval sim: $(head -c 2000 "$WORK/eval.json")"
import csv, json, sys, os, xml.etree.ElementTree as ET
d, rep = json.load(open(sys.argv[1])), sys.argv[2]
# The CSV (--csv, and the report's results.csv and per-scenario files) and the
# Markdown tables carry the same figures as the JSON.
rows = list(csv.DictReader(open(sys.argv[3])))
assert open(sys.argv[3]).read() == open(os.path.join(rep, "results.csv")).read()
assert len(rows) == sum(len(x["streams"]) for x in d["scenarios"]), len(rows)
md = open(sys.argv[4]).read()
for x in d["scenarios"]:
    per = list(csv.DictReader(open(os.path.join(rep, x["scenario"] + ".csv"))))
    assert per == [r for r in rows if r["scenario"] == x["scenario"]], x["scenario"]
    section = md.split("### " + x["scenario"] + " (")[1].split("###")[0]
    for st in x["streams"]:
        r = next(r for r in per if r["stream"] == st["stream"])
        assert r["fused"] == ("1" if st["fused"] else "0"), r
        assert abs(float(r["mean_error_cm"]) - st["mean_error_cm"]) < 1e-3, (r, st["mean_error_cm"])
        g = st["groups"]["Hands"]
        assert abs(float(r["Hands_detection_pct"]) - g["detection_pct"]) < 0.01, r
        assert abs(float(r["bone_length_sd_cm"]) - st["bone_length_sd_cm"]) < 1e-3, r
        line = next(l for l in section.splitlines() if l.startswith("| %s |" % st["stream"]))
        cells = [c.strip() for c in line.strip("|").split("|")]
        assert len(cells) == 17 and abs(float(cells[13]) - st["mean_error_cm"]) <= 0.051, (line, st["mean_error_cm"])
sc = {x["scenario"]: {s["stream"]: s for s in x["streams"]} for x in d["scenarios"]}
s = sc["360"]
det = lambda k, g: s[k]["groups"][g]["detection_pct"]
for m in ("avg", "sum"):
    for g in ("Elbows", "Hands"):
        assert det(m, g) > max(det("sensor1", g), det("sensor2", g)), (m, g, det(m, g))
best = min(s["sensor1"]["mean_error_cm"], s["sensor2"]["mean_error_cm"])
assert s["kalman"]["mean_error_cm"] < 0.75 * best, (s["kalman"]["mean_error_cm"], best)
html = open(os.path.join(rep, "report.html")).read()
# Every table row complete: 17 cells (stream, 6 groups x 2, 4 summary figures), none cut short.
from html.parser import HTMLParser
class Rows(HTMLParser):
    def __init__(self):
        super().__init__(); self.rows, self.cells, self.open = [], 0, False
    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            assert not self.open, "a <tr> inside an unclosed row"
            self.open, self.cells = True, 0
        elif tag in ("td", "th"):
            self.cells += 1
    def handle_endtag(self, tag):
        if tag == "tr":
            self.rows.append(self.cells); self.open = False
rows = Rows(); rows.feed(html)
assert rows.rows and all(n == 17 for n in rows.rows) and not rows.open, rows.rows
# 17 figures per scenario: the uncertainty's reliability, mean error, each
# group's error (6), right hand x/y/z, each group's detection timeline (6)
assert html.count("<svg") == 34 and "<table>" in html, html.count("<svg")
assert html.count("truth inside the published region (reliability)") >= 2
svgs = [f for f in os.listdir(rep) if f.endswith(".svg")]
assert len(svgs) == 34 and os.path.exists(os.path.join(rep, "arms_reliability.svg")), svgs
assert os.path.exists(os.path.join(rep, "360_error_shoulders.svg")) and os.path.exists(os.path.join(rep, "arms_torso_detected.svg"))
for f in svgs:
    root = ET.parse(os.path.join(rep, f)).getroot()   # well-formed
    assert root.tag.endswith("svg")
err = ET.parse(os.path.join(rep, "360_error.svg")).getroot()
paths = [p for p in err.iter() if p.tag.endswith("path") and len(p.get("d", "")) > 100]
assert len(paths) == 7, len(paths)   # a line per stream
print("360: kalman %.1f cm vs best single %.1f cm" % (s["kalman"]["mean_error_cm"], best))
PY
ok "eval sim: fusion beats single sensors on 360; report with $(ls "$WORK/report" | wc -l) files"

# Real data without truth (KinectMultiTrack, two Kinect v2): each recording
# calibrated from its own skeletons, then fused with those poses; kalman's
# bone lengths must be steadier than either sensor's. A 90-degree walk, and a
# 22-frame stand-still where the sensors disagree about one hand (a filter
# started from the mean of the two ran off towards one of them).
KMT=${SKELGRAPH_DATA_DIR:-$SRC/../shared/data}/kinect-multitrack/Experiments_1_2_3_6
[ -d "$KMT" ] || fail "$KMT is missing: tests read ../shared/data (or SKELGRAPH_DATA_DIR)"
for rec in Study_12_Kinect_2_Time_5_01_13_PM Study_14_Kinect_2_Time_5_52_45_PM; do
  "$SKELGRAPH" bag import multitrack "$KMT/$rec.csv" --out "$WORK/$rec.mcap" >/dev/null
  "$SKELGRAPH" calib skeleton --format multitrack "$KMT/$rec.csv" --ref kinect_138_251_213_82 --prior shared --out "$WORK/$rec.yaml" >/dev/null
  "$SKELGRAPH" eval recording "$WORK/$rec.mcap" --calibration "$WORK/$rec.yaml" --json >"$WORK/$rec.json"
  python3 - "$WORK/$rec.json" <<'PY' || fail "$rec: $(head -c 1500 "$WORK/$rec.json")"
import json, sys
st = {s["stream"]: s for s in json.load(open(sys.argv[1]))["streams"]}
single = [s["bone_length_sd_cm"] for s in st.values() if not s["fused"]]
k = st["kalman"]
assert len(single) == 2 and k["bone_length_sd_cm"] < min(single), (k["bone_length_sd_cm"], single)
assert k["upper_body_complete_pct"] >= 97.0, k["upper_body_complete_pct"]
print("bone-length SD kalman %.2f cm, sensors %.2f / %.2f cm" % (k["bone_length_sd_cm"], *single))
PY
  ok "$rec: calibrated from its skeletons, kalman steadier than both sensors"
done

# Out of time order: the same skeletons re-imported one sensor after the
# other (all of one sensor's frames, then all of the other's) score the same.
rec=Study_12_Kinect_2_Time_5_01_13_PM
"$SKELGRAPH" bag export "$WORK/$rec.mcap" --format generic --out "$WORK/csv" >/dev/null
"$SKELGRAPH" bag import generic "$WORK"/csv/raw_*.csv --out "$WORK/disordered.mcap" >/dev/null 2>&1
"$SKELGRAPH" eval recording "$WORK/disordered.mcap" --calibration "$WORK/$rec.yaml" --json >"$WORK/disordered.json"
python3 - "$WORK/$rec.json" "$WORK/disordered.json" <<'PY' || fail "disordered recording scored differently"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
assert a["ticks"] == b["ticks"] > 1000, (a["ticks"], b["ticks"])
sa, sb = ({s["stream"]: s for s in x["streams"]} for x in (a, b))
assert sa == sb, [k for k in sa if sa[k] != sb.get(k)]
PY
ok "a recording out of time order scores as the ordered one"

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
# Motion capture as the truth: the simulator's truth written as BVH (sim
# export), added to a recording of one sensor's skeletons (bag import-bvh),
# and the recording scored against it as against the simulator's own truth.
"$SKELGRAPH" sim export "$WORK/mocap" -p scenario=walk -p sensor_count=1 --json >"$WORK/mocap_export.json" 2>/dev/null
json_check "$WORK/mocap_export.json" 'd["rows"]["truth.bvh"] == d["rows"]["truth.csv"] > 100'
"$SKELGRAPH" sim poses "$WORK/mocap_poses.yaml" -p sensor_count=1 >/dev/null
"$SKELGRAPH" bag import generic "$WORK/mocap/raw_sensor1.csv" --out "$WORK/mocap_raw.mcap" >/dev/null 2>&1
t0=$(json_get "$WORK/mocap_export.json" 'd["rows"]["truth.bvh first frame s"]')
"$SKELGRAPH" bag import-bvh "$WORK/mocap/truth.bvh" --add-to "$WORK/mocap_raw.mcap" --time-offset "$t0" --out "$WORK/mocap.mcap" \
  --json >"$WORK/mocap_import.json" || fail "bag import-bvh"
json_check "$WORK/mocap_import.json" 'd["truth_frames"] > 100 and d["copied"] > 100'
rc=0
"$SKELGRAPH" bag import-bvh "$WORK/mocap/truth.bvh" --transform "$WORK/mocap_poses.yaml" --out "$WORK/x.mcap" 2>"$WORK/mocap_bad.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q "no sensor 'mocap'" "$WORK/mocap_bad.err" || fail "a calibration file without the mocap's pose: rc $rc, $(cat "$WORK/mocap_bad.err")"
"$SKELGRAPH" eval recording "$WORK/mocap.mcap" --calibration "$WORK/mocap_poses.yaml" --json >"$WORK/mocap_eval.json" \
  || fail "eval recording against the mocap"
python3 - "$WORK/mocap_eval.json" <<'PY' || fail "scored against the mocap: $(head -c 1500 "$WORK/mocap_eval.json")"
import json, sys
d = json.load(open(sys.argv[1]))
single = [s for s in d["streams"] if not s["fused"]]
assert len(single) == 1, [s["stream"] for s in d["streams"]]
s = single[0]
assert s["mean_error_cm"] is not None and 1 < s["mean_error_cm"] < 20, s["mean_error_cm"]
PY
ok "a recording scored against motion capture (BVH): sensor1 $(json_get "$WORK/mocap_eval.json" 'round([s for s in d["streams"] if not s["fused"]][0]["mean_error_cm"], 1)') cm"
echo "eval: all checks passed"
