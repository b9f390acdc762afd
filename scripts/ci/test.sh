#!/usr/bin/env bash
# Runs every check and test of vgsel-colmap; installs the system packages they need first.
set -euo pipefail
cd "$(dirname "$0")/../.."
bash scripts/ci/install-deps.sh
# networkx: the export test loads the GraphML file with it (skipped where python3 is missing).
if command -v python3 >/dev/null && ! python3 -c "import networkx" 2>/dev/null; then
  python3 -m pip install --quiet networkx
fi
# COLMAP 4 for tests/colmap4.rs: pycolmap, pinned, in a virtual environment of its own.
VGSEL_PYCOLMAP_PYTHON=$(bash scripts/ci/pycolmap-venv.sh)
export VGSEL_PYCOLMAP_PYTHON
cargo fmt --check
# The tool alone builds without the evaluation tooling, and none of its dependencies come along.
cargo clippy --quiet --no-default-features --bin vgsel-colmap -- -D warnings
if cargo tree --no-default-features -e normal --prefix none | grep -E '^(png|rand|rand_chacha|rand_distr) '; then
  echo "test.sh: the tool alone depends on the evaluation tooling's crates (above)" >&2
  exit 1
fi
cargo clippy --workspace --all-targets --quiet -- -D warnings
# Every public item documented (missing_docs) and every doc link resolved.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet
# The research lab's own tests (scripts/lab/README.md): standard-library Python, no build. Before
# cargo's, whose closing line CI reads.
python3 -m unittest discover -s scripts/lab/tests
cargo test --workspace --all-targets
