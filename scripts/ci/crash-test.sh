#!/usr/bin/env bash
# The long crash-safety run: tests/crash.rs with more kills on a bigger database (release build).
# Usage: bash scripts/ci/crash-test.sh [RUNS] [IMAGES]   (defaults 300 and 80; CI runs 20 and 40)
# Reproduce a failure with the VGSEL_CRASH_SEED it prints.
set -euo pipefail
cd "$(dirname "$0")/../.."
export VGSEL_CRASH_RUNS="${1:-300}" VGSEL_CRASH_IMAGES="${2:-80}"
# tests/crash.rs is a module of the one integration-test binary (tests/tests.rs): its tests are
# the ones whose path starts with crash::.
cargo test --release --test tests crash:: -- --nocapture
