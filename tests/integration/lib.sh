# Shared helpers for the integration scripts (sourced). They run inside
# tests/netns-lo.sh, so every process here sees only the loopback interface.
set -euo pipefail
SKELGRAPH=$(realpath "${1:?usage: $0 path/to/skelgraph}")  # absolute: some helpers run it from elsewhere
SRC=${SKELGRAPH_SOURCE_DIR:?set by ctest}
WORK=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$WORK"' EXIT
cd "$SRC"

# python3 resolved once, first on PATH for every process of the test (netns hosts included): a
# version manager's shim (pyenv here) costs 0.4 s of CPU per start, the interpreter itself 0.03 s.
mkdir "$WORK/bin"
ln -s "$(python3 -c 'import sys; print(sys.executable)')" "$WORK/bin/python3"
export PATH="$WORK/bin:$PATH"

fail() { echo "FAIL: $*" >&2; exit 1; }
ok() { echo "ok: $*"; }

# json_check FILE PYTHON_EXPR: the expression (over `d`, the parsed JSON) must be true.
json_check() {
  python3 - "$1" "$2" <<'PY' || fail "check failed: $2 on $(cat "$1")"
import json, sys
d = json.load(open(sys.argv[1]))
sys.exit(0 if eval(sys.argv[2]) else 1)
PY
}

# json_get FILE PYTHON_EXPR: prints the expression's value (for messages).
json_get() { python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$1" "$2"; }

# wait_for_match FILE PATTERN SECONDS: waits (bounded, polling) until FILE has a line matching PATTERN.
wait_for_match() {
  local file=$1 pattern=$2 deadline=$((SECONDS + $3))
  while [ "$SECONDS" -lt "$deadline" ]; do
    grep -q -- "$pattern" "$file" 2>/dev/null && return 0
    sleep 0.05
  done
  grep -q -- "$pattern" "$file" 2>/dev/null
}

# wait_for_count FILE PATTERN N SECONDS: waits (bounded, polling) until FILE has N lines matching PATTERN.
wait_for_count() {
  local file=$1 pattern=$2 n=$3 deadline=$((SECONDS + $4)) c
  while :; do
    c=$(grep -c -- "$pattern" "$file" 2>/dev/null || true)
    [ "${c:-0}" -ge "$n" ] && return 0
    [ "$SECONDS" -lt "$deadline" ] || return 1
    sleep 0.1
  done
}

# wait_until SECONDS CMD...: runs CMD (quiet) until it succeeds, polling, at most SECONDS.
wait_until() {
  local deadline=$((SECONDS + $1)); shift
  while :; do
    "$@" >/dev/null 2>&1 && return 0
    [ "$SECONDS" -lt "$deadline" ] || return 1
    sleep 0.2
  done
}

# retry N CMD...: runs CMD until it succeeds, at most N times (each try is itself bounded).
retry() {
  local n=$1; shift
  for k in $(seq "$n"); do
    "$@" && return 0
    echo "retry: attempt $k of $n failed: $*" >&2
  done
  return 1
}
