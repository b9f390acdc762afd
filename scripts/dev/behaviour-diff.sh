#!/usr/bin/env bash
# Compares what two vgsel-colmap binaries show a user on the same databases
# (scripts/dev/behaviour-snapshot.sh); prints the differences and exits 1 if there are any.
# usage: scripts/dev/behaviour-diff.sh OLD_BINARY NEW_BINARY WORKDIR DATABASE...
set -euo pipefail
[ $# -ge 4 ] || { echo "usage: $0 OLD_BINARY NEW_BINARY WORKDIR DATABASE..." >&2; exit 2; }
old=$1 new=$2 work=$3
shift 3
here=$(dirname "$0")
status=0
for db in "$@"; do
  name=$(basename "$db" .db)
  bash "$here/behaviour-snapshot.sh" "$old" "$db" "$work/$name-old"
  bash "$here/behaviour-snapshot.sh" "$new" "$db" "$work/$name-new"
  diff -r "$work/$name-old" "$work/$name-new" || status=1
done
[ $status -eq 0 ] && echo "behaviour-diff: identical on $*"
exit $status
