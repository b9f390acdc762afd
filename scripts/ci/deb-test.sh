#!/usr/bin/env bash
# Builds the Debian package (scripts/ci/deb.sh), installs it with apt beside Debian's colmap and
# runs its autopkgtest (debian/tests) against the installed files. Removes the package again
# unless it was installed before. Needs root or sudo.
set -euo pipefail
cd "$(dirname "$0")/../.."
deb=$(realpath "$(bash scripts/ci/deb.sh | tail -n 1)")
echo "package: $deb" >&2
dpkg-deb --info "$deb" | sed -n '/Depends\|Recommends/p' >&2
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
installed_before=0
dpkg -s vgsel-colmap >/dev/null 2>&1 && installed_before=1
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "$deb" colmap sqlite3 >/dev/null
status=0
for t in $(sed -n 's/^Tests: *//p' debian/tests/control); do
  tmp=$(mktemp -d)
  echo "autopkgtest $t" >&2
  AUTOPKGTEST_TMP=$tmp PATH=/usr/bin:/bin "debian/tests/$t" || status=1
  rm -rf "$tmp"
done
[ "$installed_before" -eq 1 ] || DEBIAN_FRONTEND=noninteractive $sudo apt-get remove -y -qq vgsel-colmap >/dev/null
exit $status
