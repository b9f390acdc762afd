#!/usr/bin/env bash
# Benchmarks vgsel-colmap's flow search against LEMON NetworkSimplex, OR-tools and networkx on the
# paper's synthetic graphs, all in one run; prints medians and ratios as a markdown table.
# usage: scripts/bench/solver.sh [--sizes 300x10000,1000x100000,5000x1000000] [--repeats 3]
set -euo pipefail
cd "$(dirname "$0")/../.."
bash scripts/ci/install-deps.sh
dpkg -s liblemon-dev >/dev/null 2>&1 || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq liblemon-dev >/dev/null; }
python3 -c "import ortools, networkx" 2>/dev/null || python3 -m pip install -q ortools networkx
cargo build --release --quiet
work=${BENCH_DIR:-target/bench}
mkdir -p "$work"
g++ -O2 -o "$work/lemon_search" scripts/bench/lemon_search.cpp
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')" >&2
python3 scripts/bench/bench_solver.py target/release/vgsel-colmap "$work/lemon_search" "$work" "$@"
