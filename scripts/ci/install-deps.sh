#!/usr/bin/env bash
# Installs the system packages vgsel-colmap's tests, demo and benchmarks use (Debian/Ubuntu):
# COLMAP 3.8 (real mapper runs in tests), sqlite3 (inspection in scripts), graphviz (the export
# test renders the DOT file with `dot`), python3 (the tables of scripts/pipeline.sh), and OpenCV
# with clang/libclang, which the `opencv` crate's build links against and generates bindings with.
# Does nothing for packages already installed; needs root or sudo otherwise.
set -euo pipefail
packages=(colmap sqlite3 bc graphviz python3 libopencv-dev clang libclang-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "installing: ${missing[*]}" >&2
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
