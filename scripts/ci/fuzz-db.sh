#!/usr/bin/env bash
# Database-level fuzzer (tests/fuzz_db.rs, in the `tests` binary) for SECONDS (default 600):
# mutated COLMAP databases through inspect, export, prune and restore under a watchdog. Extra inputs (e.g. COLMAP 4.x
# databases): VGSEL_FUZZ_DB_INPUTS=a.db:b.db. Replay a run: VGSEL_FUZZ_DB_SEED=N.
# Findings' databases are kept in target/tmp/fuzz-db-findings/.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-600}
VGSEL_FUZZ_DB_SECONDS=$seconds nice -n 5 cargo test --test tests fuzz_db:: -- --nocapture
