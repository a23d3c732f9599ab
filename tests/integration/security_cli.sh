#!/usr/bin/env bash
# DDS Security on one machine (loopback + credentials; the three-host secure.sh is
# disabled, see docs/security.md): `security init` and `check`, a sensor host's
# skeletons read by the master host, nothing for a participant without
# credentials, a sensor host refused as sync master, and readable errors for
# missing credentials and a tampered permissions file.
source "$(dirname "$0")/lib.sh"
"$SKELGRAPH" security init "$WORK/creds" --master fusion --sensors sensor1 --readers robot >/dev/null
"$SKELGRAPH" security check "$WORK/creds" --json >"$WORK/check.json" || fail "check: $(cat "$WORK/check.json")"
json_check "$WORK/check.json" 'd["ok"] and len(d["checks"]) == 9'
if "$SKELGRAPH" security init "$WORK/creds" --master fusion 2>"$WORK/again.err"; then fail "init over a CA accepted"; fi
grep -q "already holds a CA" "$WORK/again.err" || fail "$(cat "$WORK/again.err")"
ok "security init: CA, 3 hosts, signed governance and permissions; check passes"

if "$SKELGRAPH" run sim --profile secure --duration 1 2>"$WORK/e1"; then fail "secure profile without credentials ran"; fi
grep -q "needs security credentials" "$WORK/e1" || fail "$(cat "$WORK/e1")"
if SKELGRAPH_HOST=nobody "$SKELGRAPH" run sim --security "$WORK/creds" --duration 1 2>"$WORK/e2"; then fail "unknown host ran"; fi
grep -q "hosts/nobody.pem" "$WORK/e2" || fail "$(cat "$WORK/e2")"

SKELGRAPH_HOST=sensor1 "$SKELGRAPH" run sim --security "$WORK/creds" --duration 40 >/dev/null 2>"$WORK/sim.err" &
sim=$!
# A new secure participant sometimes fails to authenticate and the next try works (docs/security.md).
SKELGRAPH_HOST=fusion retry 3 "$SKELGRAPH" topic hz skelgraph/skeleton/raw --security "$WORK/creds" --window 2 --timeout 8 \
  --json >"$WORK/hz.json" 2>"$WORK/hz.err" || fail "the master host read nothing: $(cat "$WORK/hz.err")"
json_check "$WORK/hz.json" '50 < d["rate_hz"] < 70'
if "$SKELGRAPH" topic echo skelgraph/skeleton/raw --count 1 --timeout 4 >"$WORK/plain.out" 2>&1; then
  fail "a participant without credentials read skeletons"
fi
if SKELGRAPH_HOST=sensor1 "$SKELGRAPH" launch "$SRC/bringup/sync.yaml" --security "$WORK/creds" --duration 2 >"$WORK/sync.out" 2>&1; then
  fail "a sensor host ran a sync master"
fi
grep -q "do not let host 'sensor1' publish it" "$WORK/sync.out" || fail "$(tail -2 "$WORK/sync.out")"
kill -INT "$sim"
wait "$sim" || fail "sim: $(tail -2 "$WORK/sim.err")"
ok "master host reads a sensor host's skeletons ($(json_get "$WORK/hz.json" 'round(d["rate_hz"])') Hz); no credentials: nothing; sensor host refused as sync master"

# A permissions file changed after signing: check says so.
sed -i 's/skelgraph\/status/skelgraph\/st4tus/' "$WORK/creds/permissions.p7s"
if "$SKELGRAPH" security check "$WORK/creds" >"$WORK/bad.out" 2>&1; then fail "tampered permissions passed the check"; fi
grep -q "FAIL  permissions.p7s signed by ca.pem" "$WORK/bad.out" || fail "$(cat "$WORK/bad.out")"
ok "a tampered permissions.p7s fails the check"
