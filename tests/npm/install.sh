#!/usr/bin/env bash
# Installs the viewers' npm packages (tests/npm/package-lock.json) into DIR,
# once: a second run with the same lock file does nothing. Needs the npm registry.
set -euo pipefail
dir=${1:?usage: install.sh DIR}
src=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$dir"
if [ -d "$dir/node_modules" ] && cmp -s "$src/package-lock.json" "$dir/package-lock.json"; then
  echo "npm packages already installed in $dir"
  exit 0
fi
command -v npm >/dev/null || { echo "npm is missing (tools/run installs it)" >&2; exit 1; }
cp "$src/package.json" "$src/package-lock.json" "$src/check_mcap.mjs" "$dir/"
cd "$dir"
npm ci --no-audit --no-fund --loglevel=error 2>&1 | grep -v 'Unknown user config' || true
[ -d node_modules/@mcap/core ] || { echo "npm ci did not install @mcap/core" >&2; exit 1; }
echo "npm packages installed in $dir"
