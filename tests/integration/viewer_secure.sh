#!/usr/bin/env bash
# The viewer on an address other than loopback (issue 39): it refuses to start
# without the cell's credentials (the live viewer and `bag view`); with them it
# serves only HTTPS/WSS, and only to a viewer certificate of the cell's CA or
# a viewer token. Chromium (Playwright) gets the page and the scene with a
# token (check_secure_viewer.mjs also drives a client certificate); curl shows plain
# HTTP, a certificate of another CA, an expired one, a DDS host certificate
# (not a viewer's), a wrong, an expired and a revoked token refused; the
# refusals are counted on the viewer's status topic and in its report.
# Runs in its own network namespace with only `lo`: 0.0.0.0 reaches nothing else.
#   viewer_secure.sh SKELGRAPH BROWSER_DIR
source "$(dirname "$0")/lib.sh"
BROWSER_DIR=${2:?browser folder}
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
[ -x "$CHROMIUM" ] || fail "no Chromium at $CHROMIUM (Debian package chromium; tools/run test installs it)"
[ -f "$BROWSER_DIR/node_modules/playwright-core/package.json" ] || fail "playwright-core is not installed in $BROWSER_DIR"
export SKELGRAPH_HOST=viewhost
D=$WORK/creds
PORT=8443

"$SKELGRAPH" security init "$D" --master viewhost --readers reader1 >/dev/null
"$SKELGRAPH" security viewer "$D" --server viewhost --address 127.0.0.1,localhost --json >"$WORK/server.json"
"$SKELGRAPH" security viewer "$D" --person alice --days 2 --json >"$WORK/alice.json"
json_check "$WORK/alice.json" 'd["days"] == 2 and d["pkcs12"].endswith("alice.p12")'
"$SKELGRAPH" security token "$D" --person bob --json >"$WORK/bob.json"
TOKEN=$(json_get "$WORK/bob.json" 'd["token"]')
"$SKELGRAPH" security token "$D" --person carol --json >"$WORK/carol.json"
CAROL=$(json_get "$WORK/carol.json" 'd["token"]')
grep -q "$TOKEN" "$D/viewer/tokens" && fail "the tokens file holds a token itself, not only its hash"
# Another cell's CA, its viewer certificate for the same name; and alice's key in a certificate already expired.
"$SKELGRAPH" security init "$WORK/other" --master viewhost >/dev/null
"$SKELGRAPH" security viewer "$WORK/other" --person alice >/dev/null
(cd "$D" && openssl req -new -key viewer/people/alice.key -subj /CN=alice/OU=viewer -out "$WORK/old.csr" &&
  openssl x509 -req -in "$WORK/old.csr" -CA ca.pem -CAkey ca.key -days -1 -out "$WORK/expired.pem") 2>/dev/null
ok "credentials: a viewer server certificate, a person's certificate (.p12), two tokens (hashes only kept)"

# 1. Without credentials, nothing listens beyond loopback.
rc=0
"$SKELGRAPH" launch "$SRC/bringup/sim_dual_viewer.yaml" --set viewer.address=0.0.0.0 --set viewer.port=$PORT --duration 5 \
  >"$WORK/nocreds.out" 2>"$WORK/nocreds.err" || rc=$?
[ "$rc" -ne 0 ] || fail "the viewer started on 0.0.0.0 without credentials"
grep -q "serving on 0.0.0.0 needs the cell's credentials" "$WORK/nocreds.err" || fail "no reason given: $(tail -3 "$WORK/nocreds.err")"
grep -q "skelgraph security viewer" "$WORK/nocreds.err" || fail "the refusal does not say how to make credentials"
"$SKELGRAPH" sim export "$WORK/sim" -p scenario=walk -p sensor_count=1 >/dev/null 2>"$WORK/export.err" || fail "sim export: $(tail -3 "$WORK/export.err")"
"$SKELGRAPH" bag import generic "$WORK/sim/raw_sensor1.csv" --out "$WORK/rec.mcap" >/dev/null || fail "bag import"
rc=0
"$SKELGRAPH" view "$WORK/rec.mcap" --address 0.0.0.0 --port $PORT --duration 5 >/dev/null 2>"$WORK/view.err" || rc=$?
[ "$rc" -ne 0 ] || fail "skelgraph view served a recording on 0.0.0.0 without credentials"
grep -q "needs the cell's credentials" "$WORK/view.err" || fail "view: no reason given: $(tail -3 "$WORK/view.err")"
ok "no credentials: the live viewer and skelgraph view refuse 0.0.0.0 and say how to make them"

# 2. With them: HTTPS only, a certificate or a token for every request.
"$SKELGRAPH" launch "$SRC/bringup/sim_dual_viewer.yaml" --set viewer.address=0.0.0.0 --set viewer.port=$PORT \
  --set "viewer.credentials=$D" --duration 90 --json >"$WORK/launch.json" 2>"$WORK/launch.err" &
launch=$!
wait_for_match "$WORK/launch.err" "open https://0.0.0.0:$PORT/" 20 || fail "the secure viewer did not start: $(tail -5 "$WORK/launch.err")"
URL="https://127.0.0.1:$PORT/"
code() { curl -s -m 5 --cacert "$D/ca.pem" -o /dev/null -w '%{http_code}' "$@" || true; }
[ "$(curl -s -m 5 -o /dev/null -w '%{http_code}' "http://127.0.0.1:$PORT/" || true)" = 000 ] || fail "plain HTTP got an answer"
[ "$(code "$URL")" = 401 ] || fail "no credentials: not 401"
[ "$(code -H "Authorization: Bearer 0123abcd" "$URL")" = 401 ] || fail "a wrong token: not 401"
[ "$(code --cert "$D/hosts/reader1.pem" --key "$D/hosts/reader1.key" "$URL")" = 401 ] ||
  fail "a DDS host certificate (no viewer) was let in"
[ "$(code --cert "$WORK/other/viewer/people/alice.pem" --key "$WORK/other/viewer/people/alice.key" "$URL")" = 000 ] ||
  fail "a viewer certificate of another CA got an HTTP answer"
[ "$(code --cert "$WORK/expired.pem" --key "$D/viewer/people/alice.key" "$URL")" = 000 ] || fail "an expired certificate got an HTTP answer"
[ "$(code --cert "$D/viewer/people/alice.pem" --key "$D/viewer/people/alice.key" "$URL")" = 200 ] || fail "alice's certificate: not 200"
[ "$(code -H "Authorization: Bearer $TOKEN" "https://localhost:$PORT/three/three.module.js")" = 200 ] ||
  fail "bob's token (by its name in the server certificate): not 200"
curl -s -m 5 --cacert "$D/ca.pem" -D "$WORK/redirect.h" -o /dev/null "$URL?token=$TOKEN" || true
grep -qi "^location: /" "$WORK/redirect.h" && grep -qi "^set-cookie: skelgraph_token=$TOKEN; Secure; HttpOnly" "$WORK/redirect.h" ||
  fail "a token in the address: no redirect with a secure cookie: $(cat "$WORK/redirect.h")"
# A token whose time is over (written as security token writes it, with a past expiry), and a revoked one:
# the running viewer reads the tokens file again.
EXPIRED=feedc0de
printf '%s %s dave\n' "$(printf %s "$EXPIRED" | sha256sum | cut -d' ' -f1)" "$(($(date +%s) - 60))" >>"$D/viewer/tokens"
[ "$(code -H "Authorization: Bearer $EXPIRED" "$URL")" = 401 ] || fail "an expired token: not 401"
[ "$(code -H "Authorization: Bearer $CAROL" "$URL")" = 200 ] || fail "carol's token before revoking: not 200"
"$SKELGRAPH" security token "$D" --revoke carol --json >"$WORK/revoke.json"
json_check "$WORK/revoke.json" 'd["tokens_removed"] == 1'
[ "$(code -H "Authorization: Bearer $CAROL" "$URL")" = 401 ] || fail "a revoked token still works"
ok "curl: plain HTTP, other CA, expired certificate refused at TLS; no, wrong, expired, revoked token and a host certificate 401; certificate and token 200"

# 3. Chromium, trusting exactly the viewer's key.
PIN=$(openssl x509 -in "$D/viewer/server-viewhost.pem" -pubkey -noout | openssl pkey -pubin -outform der |
  openssl dgst -sha256 -binary | base64)
page() { CHROMIUM="$CHROMIUM" node "$BROWSER_DIR/check_secure_viewer.mjs" "$@"; }
page "$URL?token=$TOKEN" "$PIN" token >"$WORK/page-token.json" || fail "browser (token) failed"
json_check "$WORK/page-token.json" 'd.get("status") == 200 and d["cookie"] and "token" not in d["final_url"] and d["frames_drawn"] > 10 and d["skeletons"] >= 3 and not d["page_errors"]'
ok "Chromium: the scene over WSS with a token ($(json_get "$WORK/page-token.json" 'd["skeletons"]') skeletons); a client certificate: curl above"

# 4. The refusals on the status topic, and in the final report.
"$SKELGRAPH" topic echo skelgraph/status --json --count 40 --timeout 10 >"$WORK/status.jsonl" 2>/dev/null || true
python3 - "$WORK/status.jsonl" <<'PY' || fail "the viewer's status does not count the refusals: $(grep -h viewer "$WORK/status.jsonl" | tail -1)"
import json, re, sys
msgs = [json.loads(l)["data"]["message"] for l in open(sys.argv[1]) if json.loads(l)["data"]["component_name"] == "viewer"]
m = re.search(r"let in (\d+) by certificate, (\d+) by token; refused (\d+) at TLS, (\d+) without credentials", msgs[-1] if msgs else "")
sys.exit(0 if m and int(m[1]) >= 1 and int(m[2]) >= 1 and int(m[3]) == 3 and int(m[4]) >= 5 else 1)
PY
kill -INT $launch
wait $launch || fail "the launch did not end cleanly: $(tail -3 "$WORK/launch.err")"
json_check "$WORK/launch.json" '[c for c in d["components"] if c["name"] == "viewer"][0]["details"]["tls_refused"] == 3 and [c for c in d["components"] if c["name"] == "viewer"][0]["details"]["secure"]'
ok "refusals counted: $(grep -o 'let in [^|]*credentials' "$WORK/launch.err" | tail -1)"
