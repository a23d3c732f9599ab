#!/usr/bin/env bash
# Runs a command in a private network namespace whose only interface is `lo`,
# so nothing a test starts can reach any other network. Needs root (CI is root).
set -euo pipefail
if ! unshare -n true 2>/dev/null; then
  echo "netns-lo.sh: cannot create a network namespace (unshare -n needs root or CAP_SYS_ADMIN)" >&2
  exit 1
fi
exec unshare -n -- bash -c 'ip link set lo up && exec "$@"' netns-lo "$@"
