#!/usr/bin/env bash
# Runs a command in a private network namespace whose only interface is `lo`,
# so nothing a test starts can reach any other network, and in a private mount
# namespace with its own /dev/shm (a tmpfs): Fast DDS's shared-memory transport
# and data-sharing segments of one test neither meet another test's nor outlive
# it (a participant that is killed leaves its segments behind; the tmpfs goes
# with the namespace). Needs root (CI is root).
set -euo pipefail
if ! unshare -n -m true 2>/dev/null; then
  echo "netns-lo.sh: cannot create network and mount namespaces (unshare -n -m needs root or CAP_SYS_ADMIN)" >&2
  exit 1
fi
exec unshare -n -m --propagation private -- bash -c \
  'mount -t tmpfs -o size=4g,mode=1777 skelgraph-test-shm /dev/shm && ip link set lo up && exec "$@"' netns-lo "$@"
