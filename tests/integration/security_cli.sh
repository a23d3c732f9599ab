#!/usr/bin/env bash
# DDS Security on one machine (loopback + credentials; the three-host secure.sh is
# disabled, see docs/security.md): `security init` and `check`, a sensor host's
# skeletons read by the master host, nothing for a participant without
# credentials, a sensor host refused as sync master, and readable errors for
# missing credentials and a tampered permissions file.
source "$(dirname "$0")/lib.sh"
"$SKELGRAPH" security init "$WORK/creds" --master fusion --sensors sensor1 --readers robot >/dev/null
"$SKELGRAPH" security check "$WORK/creds" --json >"$WORK/check.json" || fail "check: $(cat "$WORK/check.json")"
json_check "$WORK/check.json" 'd["ok"] and len(d["checks"]) == 12 and d["hosts"]["robot"]["roles"] == ["reader"] and not d["hosts"]["fusion"]["robot_commands"]'
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
json_check "$WORK/hz.json" 'd["samples"] >= 20'
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

# Robot roles (issue 39): only the robot host publishes its state; only robot-control hosts
# command it, not even the master; the robot itself takes commands only from sources it knows.
"$SKELGRAPH" security init "$WORK/rc" --master fusion --sensors sensor1 --readers reader1 --robots arm \
  --robot-control control --json >"$WORK/rc.json"
json_check "$WORK/rc.json" 'd["hosts"]["fusion"]["denied"] == ["skelgraph/robot/state", "skelgraph/robot/command", "skelgraph/safety"] and d["hosts"]["control"]["publishes"][:2] == ["skelgraph/robot/command", "skelgraph/safety"]'
"$SKELGRAPH" security check "$WORK/rc" --json >"$WORK/rc-check.json" || fail "check: $(cat "$WORK/rc-check.json")"
json_check "$WORK/rc-check.json" 'd["hosts"]["control"]["robot_commands"] and not d["hosts"]["fusion"]["robot_commands"] and not d["hosts"]["arm"]["robot_commands"]'
if "$SKELGRAPH" security init "$WORK/rc2" --master fusion --readers fusion 2>"$WORK/rc2.err"; then fail "a reader that is also master accepted"; fi
grep -q "a reader has no other role" "$WORK/rc2.err" || fail "$(cat "$WORK/rc2.err")"
if SKELGRAPH_HOST=sensor1 "$SKELGRAPH" run robot --security "$WORK/rc" --duration 2 >"$WORK/s1robot.out" 2>&1; then
  fail "a sensor host ran the robot"
fi
grep -q "could not create a writer on skelgraph/robot/state (security: the permissions do not let host 'sensor1'" \
  "$WORK/s1robot.out" || fail "$(tail -2 "$WORK/s1robot.out")"
SKELGRAPH_HOST=arm "$SKELGRAPH" run robot --security "$WORK/rc" --duration 60 --json >"$WORK/arm.json" 2>"$WORK/arm.err" &
arm=$!
for h in reader1 fusion; do
  if SKELGRAPH_HOST=$h "$SKELGRAPH" robot stop --security "$WORK/rc" --timeout 5 >"$WORK/$h.robot" 2>&1; then
    fail "$h's robot stop went out"
  fi
  grep -q "could not create a writer on skelgraph/robot/command (security: the permissions do not let host '$h'" \
    "$WORK/$h.robot" || fail "$h: $(tail -2 "$WORK/$h.robot")"
done
if "$SKELGRAPH" robot stop --timeout 3 >"$WORK/stranger.robot" 2>&1; then fail "a stranger's robot stop was acknowledged"; fi
grep -q "no state of a robot" "$WORK/stranger.robot" || fail "stranger: $(cat "$WORK/stranger.robot")"
if SKELGRAPH_HOST=control "$SKELGRAPH" robot stop --security "$WORK/rc" --source mallory --timeout 6 --json \
  >"$WORK/mallory.json" 2>"$WORK/mallory.err"; then
  fail "the robot took a stop from an unknown source"
fi
json_check "$WORK/mallory.json" 'd["sent"] >= 1 and not d["taken"]'
SKELGRAPH_HOST=control retry 3 "$SKELGRAPH" robot stop --security "$WORK/rc" --timeout 10 --json >"$WORK/op.json" ||
  fail "control: not taken"
json_check "$WORK/op.json" 'd["taken"]'
kill -INT "$arm"
wait "$arm" || fail "robot: $(tail -2 "$WORK/arm.err")"
json_check "$WORK/arm.json" 'd["components"][0]["details"]["protective_stops"] == 1 and d["components"][0]["details"]["refused_source"] >= 1 and "mallory" in d["components"][0]["details"]["last_refusal"] and d["components"][0]["details"]["stopped"]'
grep -q "refused a command from 'mallory'" "$WORK/arm.err" || fail "the robot did not say it refused mallory: $(tail -3 "$WORK/arm.err")"
ok "robot roles: a sensor host cannot be the robot; the reader and the master cannot command it, a stranger finds none; robot-control stops it; an unknown source refused and said"

# The viewer's credentials: what the tool refuses.
if "$SKELGRAPH" security viewer "$WORK/rc" --server fusion 2>"$WORK/v1.err"; then fail "a server certificate without addresses"; fi
grep -q "needs --address" "$WORK/v1.err" || fail "$(cat "$WORK/v1.err")"
if "$SKELGRAPH" security viewer "$WORK/rc" --server fusion --person alice --address 127.0.0.1 2>"$WORK/v2.err"; then fail "both --server and --person"; fi
if "$SKELGRAPH" security token "$WORK/nowhere" --person bob 2>"$WORK/v3.err"; then fail "a token without a cell"; fi
grep -q "holds no cell CA" "$WORK/v3.err" || fail "$(cat "$WORK/v3.err")"
mkdir -p "$WORK/rc/viewer" && printf 'garbage\n' >"$WORK/rc/viewer/tokens"
if "$SKELGRAPH" security token "$WORK/rc" --person bob 2>"$WORK/v4.err"; then fail "a damaged tokens file was written over"; fi
grep -q "tokens:1: expected" "$WORK/v4.err" || fail "$(cat "$WORK/v4.err")"
ok "security viewer/token: missing addresses, two kinds at once, no cell, a damaged tokens file: refused with the reason"
