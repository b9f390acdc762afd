#!/usr/bin/env bash
# Builds the Debian package target/debian/vgsel-colmap_VERSION_ARCH.deb with cargo-deb
# (installed from crates.io when missing): the release binary, its man page, bash/zsh/fish
# completions, the README and the repair loop's scripts (vgsel-colmap-pipeline); dependencies on
# the OpenCV libraries it links come from dpkg-shlibdeps, `colmap` is recommended (Cargo.toml,
# [package.metadata.deb]). Prints the path.
set -euo pipefail
cd "$(dirname "$0")/../.."
command -v cargo-deb >/dev/null || cargo install cargo-deb --locked --quiet
cargo build --release --quiet
assets=target/deb-assets
rm -rf "$assets"
mkdir -p "$assets"
bin=target/release/vgsel-colmap
"$bin" man | gzip -9n >"$assets/vgsel-colmap.1.gz"
"$bin" completions bash >"$assets/vgsel-colmap.bash"
"$bin" completions zsh >"$assets/_vgsel-colmap"
"$bin" completions fish >"$assets/vgsel-colmap.fish"
# The repair loop's command: the package's copy of scripts/pipeline.sh.
printf '#!/bin/sh\nexec /usr/share/vgsel-colmap/scripts/pipeline.sh "$@"\n' >"$assets/vgsel-colmap-pipeline"
cargo deb --no-build --strip --quiet
