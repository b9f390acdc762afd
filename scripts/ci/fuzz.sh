#!/usr/bin/env bash
# Fuzzes the blob decoders and `solve`'s graph parser with cargo-fuzz (libFuzzer), one target
# after the other, SECONDS each (default 600), at the lowest CPU priority.
# Usage: bash scripts/ci/fuzz.sh [SECONDS] [TARGET...]   (targets: decode_blobs graph_parse)
# cargo-fuzz needs nightly -Z flags; RUSTC_BOOTSTRAP=1 lets the stable toolchain accept them.
# No sanitizer (-s none): the targets are safe Rust, and a panic is what they look for.
# Crashes land in fuzz/artifacts/TARGET/; turn each into a regression test in tests/.
set -euo pipefail
cd "$(dirname "$0")/../../fuzz"
seconds="${1:-600}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(decode_blobs graph_parse)
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
export RUSTC_BOOTSTRAP=1
for t in "${targets[@]}"; do
  mkdir -p "corpus/$t"
  # A valid graph to start from, so the parser's accepting paths are reached at once.
  [ "$t" != graph_parse ] || printf '3 2\n-0.5\n0\n-1\n0 1 -0.25\n1 2 0\n' > corpus/graph_parse/seed
  echo "fuzzing $t for $seconds s" >&2
  nice -n 19 cargo fuzz run -s none "$t" "corpus/$t" -- -max_total_time="$seconds" -max_len=4096
done
