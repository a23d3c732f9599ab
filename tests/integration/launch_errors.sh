#!/usr/bin/env bash
# Bad input gets a clear message and exit code 2; every command has --help.
source "$(dirname "$0")/lib.sh"

expect_error() {  # expect_error "needle" args...
  local needle=$1; shift
  set +e
  "$SKELGRAPH" "$@" >"$WORK/out" 2>"$WORK/err"
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || fail "'skelgraph $*' exited $rc, expected 2 (stderr: $(cat "$WORK/err"))"
  grep -qF -- "$needle" "$WORK/err" || fail "'skelgraph $*' stderr lacks '$needle': $(cat "$WORK/err")"
  ok "skelgraph $* -> exit 2: $(head -1 "$WORK/err")"
}

expect_error "cannot open launch file" launch "$WORK/missing.yaml"
printf 'components:\n  - name: sync\n    type: sync_master\n    params:\n      tick_perod_ms: 5\n' >"$WORK/typo.yaml"
expect_error "typo.yaml:5:7: component 'sync' (sync_master): unknown parameter 'tick_perod_ms'" launch "$WORK/typo.yaml"
printf 'components:\n  - name: f\n    type: fusion_x\n' >"$WORK/type.yaml"
expect_error "type.yaml:2:5: component 'f' has unknown type 'fusion_x'" launch "$WORK/type.yaml"
printf 'components:\n  - name: s\n    type: sync_master\n    params: {tick_period_ms: fast}\n' >"$WORK/value.yaml"
expect_error "parameter 'tick_period_ms' expects number" launch "$WORK/value.yaml"
printf 'components: [\n' >"$WORK/yaml.yaml"
expect_error "not valid YAML" launch "$WORK/yaml.yaml"
expect_error "no components for host 'nowhere'" launch bringup/sync.yaml --host nowhere
expect_error "duration" launch bringup/sync.yaml --duration -3
expect_error "required" topic echo
expect_error "nope" nope
expect_error "unknown component type 'fusionx'" run fusionx
expect_error "--param tick=3: component 'sync_master' (sync_master): unknown parameter 'tick'" run sync_master -p tick=3
expect_error "expected KEY=VALUE" run sync_master -p tick

for cmd in "" "launch" "run" "play-data" "topic" "topic list" "topic echo" "topic hz" "sync" "sync start" "sync stop" "demo" "components"; do
  # shellcheck disable=SC2086
  "$SKELGRAPH" $cmd --help >"$WORK/help" || fail "skelgraph $cmd --help failed"
  grep -q "Usage" "$WORK/help" || fail "skelgraph $cmd --help printed no usage"
done
ok "--help on every command"
echo "launch_errors: all checks passed"
