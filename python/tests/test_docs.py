"""The documented commands run as written, so the docs cannot go stale.

Every fenced ``sh`` block of README.md, docs/guide.md and docs/modes.md is
run by bash (``set -euo pipefail``), in order, in one temporary folder
holding a copy of ``examples/``, with the ``topovox`` binary of this
checkout first on PATH. ``text`` blocks are synopses with placeholders and
are not run. Two lines are handled on purpose, not skipped silently:

- ``cargo run --release -p topovox-cli -- ARGS`` (README's first set-up
  command) is the binary this suite already runs: it becomes
  ``topovox ARGS``;
- ``bash scripts/test-all.sh`` (README's second set-up command) is what is
  running these tests, so it is not run again from inside them.

Blocks that use the GPU (``--gpu``, ``--method gpu``) need a GPU adapter;
without one they are skipped, unless TOPOVOX_REQUIRE_GPU=1 (CI), where
they must run. README's ``python`` block runs too, in the same folder.
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

from conftest import REPO

DOCS = ["README.md", "docs/guide.md", "docs/modes.md"]
SETUP_RUN = "cargo run --release -p topovox-cli -- "
SETUP_TESTS = "bash scripts/test-all.sh"


def blocks(doc: str, lang: str):
    text = (REPO / doc).read_text(encoding="utf-8")
    return [m.group(1) for m in re.finditer(r"^```" + lang + r"\n(.*?)^```$", text, flags=re.S | re.M)]


def script_of(block: str) -> str:
    lines = []
    for line in block.splitlines():
        if line.strip() == SETUP_TESTS:
            continue
        lines.append(line.replace(SETUP_RUN, "topovox "))
    return "\n".join(lines)


def uses_gpu(block: str) -> bool:
    return "--gpu" in block or "--method gpu" in block


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, cli):
    d = tmp_path_factory.mktemp("docs")
    shutil.copytree(REPO / "examples", d / "examples")
    # As in a checkout after `cargo run`: README's first command writes there.
    (d / "target").mkdir()
    bindir = d / "bin"
    bindir.mkdir()
    (bindir / "topovox").symlink_to(pathlib.Path(cli).resolve())
    return d


def env_for(workdir):
    env = dict(os.environ)
    env["PATH"] = f"{workdir / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    return env


@pytest.fixture(scope="module")
def has_gpu(workdir):
    r = subprocess.run(
        ["topovox", "voxelize", "examples/meshes/box.obj", "-o", "probe.npy", "--resolution", "4", "--method", "gpu", "--quiet"],
        cwd=workdir,
        env=env_for(workdir),
        capture_output=True,
        text=True,
    )
    return r.returncode == 0


def test_the_docs_have_commands_and_the_setup_commands_are_the_ones_handled():
    readme = blocks("README.md", "sh")
    assert readme, "README.md has no sh block"
    setup = readme[0].splitlines()
    assert any(line.startswith(SETUP_RUN) for line in setup), setup
    assert SETUP_TESTS in setup, setup
    for doc in DOCS[1:]:
        assert blocks(doc, "sh"), f"{doc} has no sh block"


@pytest.mark.parametrize("doc", DOCS)
def test_every_sh_block_runs(doc, workdir, has_gpu):
    require_gpu = os.environ.get("TOPOVOX_REQUIRE_GPU") == "1"
    ran = 0
    for n, block in enumerate(blocks(doc, "sh")):
        if uses_gpu(block) and not has_gpu:
            assert not require_gpu, f"{doc} block {n} needs a GPU and TOPOVOX_REQUIRE_GPU=1, but no adapter answered"
            continue
        r = subprocess.run(
            ["bash", "-euo", "pipefail", "-c", script_of(block)],
            cwd=workdir,
            env=env_for(workdir),
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert r.returncode == 0, f"{doc}, sh block {n} failed (exit {r.returncode}):\n{block}\n--- stderr:\n{r.stderr[-3000:]}"
        ran += 1
    assert ran > 0


def test_readme_python_block_runs(workdir):
    (code,) = blocks("README.md", "python")
    r = subprocess.run([sys.executable, "-c", code], cwd=workdir, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"README's python block failed:\n{r.stderr[-3000:]}"
