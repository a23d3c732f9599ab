#!/usr/bin/env bash
# A cell that runs all day, in short: 30 different people come into a
# simulated three-sensor cell one after another, work and leave (sim scenario
# `shift` at 5x; bringup/shift.yaml), watched by fusion, gesture, a recorder
# and the viewer, with `eval presence` listening from another process. Fails
# if any writer drops a sample, if an instance of someone who left stays
# alive, if a departure is not seen (or seen late), or if a person is not
# watched by gesture or kept by the recorder.
source "$(dirname "$0")/lib.sh"

# Another process listens to it all: `eval presence` (what crosses between
# processes is what a robot on the network would get).
"$SKELGRAPH" eval presence --duration 200 --json --check >"$WORK/presence.json" 2>"$WORK/presence.err" &
presence=$!
wait_for_match "$WORK/presence.err" "\[start\] presence" 10 || fail "eval presence did not start: $(cat "$WORK/presence.err")"
# The sim ends with the shift (about 30 s at 5x); the graph stops then.
"$SKELGRAPH" launch "$SRC/bringup/shift.yaml" --duration 120 --json \
  --set cell.people=3 --set cell.repeats=10 --set cell.work_s=3 --set cell.rate=5 \
  --set recorder.directory="$WORK/rec" --set viewer.port=0 >"$WORK/launch.json" 2>"$WORK/launch.err" ||
  fail "launch failed: $(tail -20 "$WORK/launch.err")"
kill -INT "$presence"
wait "$presence" || fail "eval presence --check: $(grep -v '^\[' "$WORK/presence.err" | tail -5)"
file=$(ls "$WORK"/rec/*.mcap | head -1)
"$SKELGRAPH" bag export "$file" --format generic --out "$WORK/export" --json >"$WORK/export.json"
python3 - "$WORK/launch.json" "$WORK/export" "$WORK/presence.json" <<'PY' || fail "lifecycle: $(tail -5 "$WORK/launch.err")"
import csv, glob, json, os, sys
comps = {c["name"]: c for c in json.load(open(sys.argv[1]))["components"]}
p = json.load(open(sys.argv[3]))
errors = []
def check(cond, what):
    if not cond:
        errors.append(what)
check(comps["cell"]["details"]["finished"], "the shift did not finish")
check(p["people"]["seen"] == 30 and p["people"]["left"] == 30, f"people: {p['people']}")
# No writer dropped anything, and every component ends OK (a failed write
# would make it DEGRADED). (A keep-last reader falling behind may lose samples
# by design; a reader that had no room would be DEGRADED too.)
for name, c in comps.items():
    check(c["state"] == "OK", f"{name} ended {c['state']}: {c.get('message')}")
    for endpoint in c.get("io", "").split(", "):
        check(not (endpoint.startswith("out ") and "dropped" in endpoint), f"{name}: {endpoint}")
check(p["failed_writes"] == 0, f"failed writes: {p['failed_writes']}")
# Nobody is left in the cell, so no instance of a person is alive; while they
# were there, at most one instance per person (per sensor for raw skeletons).
people_topics = ("skelgraph/skeleton/raw", "skelgraph/skeleton/fused", "skelgraph/skeleton/truth", "skelgraph/gesture/state")
seen_topics = set()
for o in p["outputs"]:
    if o["topic"] in people_topics:
        seen_topics.add(o["topic"])
        check(o["instances"] == 0, f"{o['component']} {o['topic']}: {o['instances']} instance(s) alive with nobody there")
        check(o["max_instances_over_people"] <= 1, f"{o['component']} {o['topic']}: {o['max_instances_over_people']} instance(s) beyond the people there")
check(seen_topics == set(people_topics), f"status of people topics: {sorted(seen_topics)}")
# Every departure seen by the reader, within 1 s of the trackers letting go.
d = p["departures"]
check(d["people"] == 30 and d["seen"] == 30 and d["late"] == 0 and d["still_shown"] == 0, f"departures: {d}")
check(d["after_inputs_ms"] is not None and d["after_inputs_ms"]["max"] < 1000, f"departures: {d}")
check(p["people"]["never_shown"] == 0, f"never shown: {p['people']}")
check(p["fused"]["alive"] == 0 and p["raw"]["alive"] == 0, f"still alive at the reader: {p['fused']} {p['raw']}")
# Every fused person watched by gesture (and let go), and kept by the recorder.
fused_people = p["fused"]["instances_seen"]
g = comps["gesture"]["details"]
check(g["people_seen"] == fused_people and g["people_left"] == fused_people and g["people"] == 0,
      f"gesture watched {g['people_seen']} of {fused_people} fused people, let {g['people_left']} go, holds {g['people']}")
ids = set()
for path in glob.glob(os.path.join(sys.argv[2], "**", "*fused*"), recursive=True):
    with open(path) as f:
        for row in csv.DictReader(l for l in f if not l.startswith("#")):
            ids.add(row["person_id"])
check(len(ids) == fused_people, f"the recording holds {len(ids)} fused people of {fused_people}")
# The launch's own presence reads keep-last like any reader: on a busy machine
# it may lose the few raw skeletons of someone tracked only briefly, and then
# counts them as never tracked (so not as a departure); everyone else's
# departure it must see, in time.
inproc = comps["presence"]["details"]
di = inproc["departures"]
check(inproc["people"]["seen"] == 30 and inproc["failed_writes"] == 0 and di["people"] >= 27 and
      di["seen"] == di["people"] and di["late"] == 0 and di["still_shown"] == 0,
      f"the launch's own presence: {inproc['people']} {di}")
check(comps["fusion"]["details"]["departed"] == fused_people, f"fusion disposed {comps['fusion']['details']['departed']} of {fused_people}")
if errors:
    print("\n".join(errors))
    sys.exit(1)
print(f"30 people, {fused_people} fused people; departures seen {d['after_inputs_ms']['max']:.0f} ms at most after the trackers let go; "
      f"shown {100 * p['completeness']['shown_of_tracked']:.0f} % of the time tracked")
PY
ok "30 people came and went: no write failed, no instance left behind, every departure seen, everyone watched and recorded"
