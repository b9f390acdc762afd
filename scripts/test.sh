#!/usr/bin/env bash
# Runs every check and test of vgsel-colmap; installs the system packages they need first.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cargo fmt --check
cargo clippy --all-targets --quiet -- -D warnings
cargo test --all-targets
