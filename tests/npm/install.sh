#!/usr/bin/env bash
# Installs a test folder's npm packages (its package-lock.json) into DIR, once:
# a second run with the same lock file only refreshes the scripts. Needs the npm registry.
#   install.sh DIR [SRC]   SRC: the folder with package.json (default: tests/npm)
set -euo pipefail
dir=${1:?usage: install.sh DIR [SRC]}
src=$(cd "${2:-$(dirname "$0")}" && pwd)
mkdir -p "$dir"
# The scripts always (they change more often than the packages).
cp "$src"/*.mjs "$dir/"
if [ -d "$dir/node_modules" ] && cmp -s "$src/package-lock.json" "$dir/package-lock.json"; then
  echo "npm packages already installed in $dir"
  exit 0
fi
command -v npm >/dev/null || { echo "npm is missing (tools/run installs it)" >&2; exit 1; }
cp "$src/package.json" "$src/package-lock.json" "$dir/"
cd "$dir"
npm ci --no-audit --no-fund --loglevel=error 2>&1 | grep -v 'Unknown user config' || true
for dep in $(node -e 'console.log(Object.keys(require("./package.json").dependencies).join(" "))'); do
  [ -f "node_modules/$dep/package.json" ] || { echo "npm ci did not install $dep" >&2; exit 1; }
done
echo "npm packages installed in $dir"
