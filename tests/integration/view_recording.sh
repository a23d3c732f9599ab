#!/usr/bin/env bash
# A recording in the browser (issue 10): `skelgraph view FILE --paused` plays it
# with the viewer; the page's own controls (Play, speed, Pause, the timeline,
# Step) drive the player, as does `skelgraph player seek`.
#   view_recording.sh SKELGRAPH BROWSER_DIR
source "$(dirname "$0")/lib.sh"
BROWSER_DIR=${2:?browser folder}
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
[ -x "$CHROMIUM" ] || fail "no Chromium at $CHROMIUM (Debian package chromium; tools/run test installs it)"
SHOT=${SKELGRAPH_VIEWER_SCREENSHOT_DIR:-$(cd "$(dirname "$SKELGRAPH")/.." && pwd)}/viewer-recording-screenshot.png
URL="http://127.0.0.1:8090/"

# A 6 s recording of the simulated two-sensor cell.
"$SKELGRAPH" launch bringup/sim_dual.yaml --duration 60 >/dev/null 2>"$WORK/sim.err" &  # stopped once recorded
sim=$!
"$SKELGRAPH" bag record --now --dir "$WORK/rec" --duration 6 >/dev/null 2>"$WORK/rec.err" || fail "bag record: $(tail -3 "$WORK/rec.err")"
kill -INT "$sim"; wait "$sim" || true
FILE=$(ls "$WORK"/rec/*.mcap)
ok "recorded $FILE"

"$SKELGRAPH" view "$FILE" --paused --port 8090 --json >"$WORK/view.json" 2>"$WORK/view.err" &
view=$!
wait_for_match "$WORK/view.err" "open $URL" 20 || fail "the viewer did not print its address: $(tail -3 "$WORK/view.err")"
"$SKELGRAPH" player state --timeout 30 --json >"$WORK/state0.json" || fail "no player state"
# The player's length is the file's (bag info); the recording has most of its 6 s (on a busy machine the
# first skeletons arrive later).
"$SKELGRAPH" bag info "$FILE" --json >"$WORK/info.json" || fail "bag info"
file_s=$(json_get "$WORK/info.json" '(d[0] if isinstance(d, list) else d)["duration_s"]')
json_check "$WORK/state0.json" "d[0]['paused'] and d[0]['frames'] == 0 and abs(d[0]['duration_s'] - $file_s) < 0.05 and 4.0 < d[0]['duration_s'] < 6.3 and d[0]['position_s'] == 0"
ok "view: paused at 0 s of $(json_get "$WORK/state0.json" 'round(d[0]["duration_s"], 2)') s"

CHROMIUM="$CHROMIUM" node "$BROWSER_DIR/check_timeline.mjs" "$URL" "$SHOT" >"$WORK/timeline.json" || fail "the browser check failed"
python3 - "$WORK/timeline.json" <<'PY' || fail "the page's controls did not drive the player (above)"
import json, sys
d = json.load(open(sys.argv[1]))
bad = [s for s in d["steps"] if not s["ok"]]
for s in d["steps"]:
    st = s.get("state") or {}
    print(f"  {'ok ' if s['ok'] else 'BAD'} {s['what']}: paused={st.get('paused')} speed={st.get('speed')} "
          f"position={st.get('position_s')} frames={st.get('frames')} at_end={st.get('at_end')}")
if d["page_errors"]: print("page errors:", d["page_errors"])
sys.exit(1 if bad or d["page_errors"] else 0)
PY
ok "the page's Play, speed, Pause, timeline and Step drove the player"

# The same from the command line; nonsense refused.
"$SKELGRAPH" player seek --timeout 30 2.5 >/dev/null || fail "player seek"
"$SKELGRAPH" player pause --timeout 30 >/dev/null || fail "player pause"
# The seek is answered once the player is there: the answer itself, and any state after it, carry the position.
"$SKELGRAPH" player seek --timeout 30 2.5 --json >"$WORK/seek.json" || fail "player seek --json"
json_check "$WORK/seek.json" 'd[0]["paused"] and abs(d[0]["position_s"] - 2.5) < 0.05 and not d[0]["at_end"]'
"$SKELGRAPH" player state --timeout 30 --json >"$WORK/state1.json"
json_check "$WORK/state1.json" 'd[0]["paused"] and abs(d[0]["position_s"] - 2.5) < 0.05 and not d[0]["at_end"]'
if "$SKELGRAPH" player seek --timeout 30 -- -1 2>"$WORK/neg.err"; then fail "a negative seek was accepted"; fi
ok "player seek 2.5 from the command line; a negative position refused"

kill -INT "$view"
wait "$view" || fail "view did not end cleanly: $(tail -3 "$WORK/view.err")"
json_check "$WORK/view.json" '[c for c in d["components"] if c["name"] == "viewer"][0]["details"]["play_requests"] >= 6'
ok "view ended cleanly; the page sent $(json_get "$WORK/view.json" '[c for c in d["components"] if c["name"] == "viewer"][0]["details"]["play_requests"]') play requests"
