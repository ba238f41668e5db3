#!/usr/bin/env bash
# Every test of topovox: the Rust workspace (cargo test), then the Python
# package built from this checkout and its pytest suite (CLI parity,
# arrays, errors, formats, batches, Dask and Ray). Works on a fresh machine
# with the Rust toolchain and Python >= 3.9: it makes its own virtual
# environment in target/venv.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== cargo test --workspace --release"
cargo test --workspace --release

echo "== Python package (maturin, abi3 wheel) into target/venv"
PY="${PYTHON:-python3}"
if [ ! -x target/venv/bin/python ]; then
    "$PY" -m venv target/venv
fi
VPY=target/venv/bin/python
"$VPY" -m pip install --quiet --disable-pip-version-check --upgrade pip
"$VPY" -m pip install --quiet --disable-pip-version-check maturin numpy pytest trimesh "dask[bag]" distributed ray fsspec
"$VPY" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps ./python

echo "== pytest"
# Run from the repository root so `import topovox` finds the installed
# package, not the sources in python/topovox.
TOPOVOX_BIN="$PWD/target/release/topovox" "$VPY" -m pytest -q python/tests
