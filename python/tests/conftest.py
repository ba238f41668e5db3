"""Shared fixtures: the shared meshes, the CLI binary built from the same
sources, and temporary folders."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def shared_meshes() -> pathlib.Path:
    """$TOPOVOX_SHARED/meshes, else ../shared/meshes, else what
    scripts/test-meshes.sh fetched into target/test-meshes."""
    env = os.environ.get("TOPOVOX_SHARED")
    if env:
        d = pathlib.Path(env) / "meshes"
    else:
        d = next((c for c in (REPO.parent / "shared" / "meshes", REPO / "target" / "test-meshes" / "meshes") if c.is_dir()), REPO.parent / "shared" / "meshes")
    if not d.is_dir():
        pytest.fail(f"shared meshes not found at {d} (set TOPOVOX_SHARED, or fetch them: bash scripts/test-meshes.sh)")
    return d


@pytest.fixture(scope="session")
def meshes() -> pathlib.Path:
    return shared_meshes()


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The `topovox` binary: $TOPOVOX_BIN, else target/release/topovox (built if missing)."""
    env = os.environ.get("TOPOVOX_BIN")
    path = pathlib.Path(env) if env else REPO / "target" / "release" / "topovox"
    if not path.exists():
        subprocess.run(["cargo", "build", "--release", "-p", "topovox-cli"], cwd=REPO, check=True)
    return path


def run_cli(cli, *args, check=True):
    return subprocess.run([str(cli), *map(str, args)], check=check, capture_output=True, text=True)
