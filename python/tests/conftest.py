"""Shared fixtures: the shared meshes, the CLI binary built from the same
sources, and temporary folders."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def shared_meshes() -> pathlib.Path:
    env = os.environ.get("TOPOVOX_SHARED")
    root = pathlib.Path(env) if env else REPO.parent / "shared"
    d = root / "meshes"
    if not d.is_dir():
        pytest.fail(f"shared meshes not found at {d} (set TOPOVOX_SHARED)")
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
