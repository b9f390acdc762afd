#!/usr/bin/env bash
# Creates the virtual environment holding COLMAP 4 (pycolmap, pinned) that tests/colmap4.rs and
# the Python recipe run, and prints its python. Idempotent: when the venv already has the pinned
# version it only prints the path. Never installs into the system Python.
#   VGSEL_PYCOLMAP_VENV  where the venv goes (default: target/pycolmap-venv of this checkout;
#                        run from the package's copy, ~/.cache/vgsel-colmap/pycolmap-venv)
#   PYTHON               the interpreter to create it with (default: python3)
set -euo pipefail
cd "$(dirname "$0")/../.."
version=4.2.1
default=$PWD/target/pycolmap-venv
[ -f Cargo.toml ] || default=${XDG_CACHE_HOME:-$HOME/.cache}/vgsel-colmap/pycolmap-venv
venv=${VGSEL_PYCOLMAP_VENV:-$default}
py=$venv/bin/python
if [ -x "$py" ] && [ "$("$py" -c 'import pycolmap; print(pycolmap.__version__)' 2>/dev/null)" = "$version" ]; then
  echo "$py"
  exit 0
fi
echo "creating $venv with pycolmap==$version" >&2
rm -rf "$venv"
"${PYTHON:-python3}" -m venv "$venv"
"$py" -m pip install --quiet --disable-pip-version-check "pycolmap==$version" >&2
"$py" -c 'import pycolmap; print("pycolmap", pycolmap.__version__, file=__import__("sys").stderr)'
echo "$py"
