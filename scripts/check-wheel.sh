#!/usr/bin/env bash
# The wheel as a user gets it: the one scripts/test-all.sh built with
# `maturin build --release` (target/dist), checked by twine, installed
# into a fresh virtual environment that holds nothing else of ours (pip
# brings NumPy, its only dependency), and the quick start of
# python/README.md (its first `python` block) run there, outside the
# checkout, as a new user would.
set -euo pipefail
cd "$(dirname "$0")/.."

wheels=(target/dist/topovox-*.whl)
if [ ! -f "${wheels[0]}" ]; then
    echo "no wheel in target/dist: run scripts/test-all.sh first (it builds it)" >&2
    exit 1
fi
echo "== twine check ${wheels[*]}"
target/venv/bin/python -m pip install --quiet --disable-pip-version-check twine
target/venv/bin/python -m twine check --strict "${wheels[@]}"

fresh="$(mktemp -d)"
trap 'rm -rf "$fresh"' EXIT
echo "== a fresh virtual environment with only the wheel: $fresh"
"${PYTHON:-python3}" -m venv "$fresh/venv"
"$fresh/venv/bin/python" -m pip install --quiet --disable-pip-version-check "${wheels[@]}"
"$fresh/venv/bin/python" -m pip list --disable-pip-version-check --format=freeze

echo "== python/README.md's quick start, in an empty folder"
"$fresh/venv/bin/python" - python/README.md > "$fresh/quickstart.py" <<'EOF'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
blocks = re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)
if not blocks:
    sys.exit("python/README.md has no python block")
print(blocks[0])
EOF
mkdir "$fresh/work"
(cd "$fresh/work" && "$fresh/venv/bin/python" ../quickstart.py)
echo "wheel checked"
