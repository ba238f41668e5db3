"""Defects users found (issue 45, item 5): errors of the kinds the README
promises, messages that say what is allowed, names in any case, bytes
paths, and a looping link that skips itself rather than the batch."""

import os
import pathlib

import numpy as np
import pytest

import topovox

REPO = pathlib.Path(__file__).resolve().parents[2]
TETRA = (
    np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float),
    np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
)


def test_saving_into_a_missing_folder_is_file_not_found(tmp_path):
    g = topovox.voxelize(*TETRA, resolution=8)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        g.save(tmp_path / "no" / "such" / "x.npy")
    (tmp_path / "d.npy").mkdir()
    with pytest.raises(IsADirectoryError):
        g.save(tmp_path / "d.npy")


@pytest.mark.parametrize("resolution", [-1, 0])
def test_a_resolution_below_one_says_at_least_one(resolution):
    with pytest.raises(ValueError, match="resolution must be at least 1"):
        topovox.voxelize(*TETRA, resolution=resolution)


def test_mode_and_method_names_take_any_case():
    a = topovox.voxelize(*TETRA, resolution=12, mode="Sep26", method="FAST")
    b = topovox.voxelize(*TETRA, resolution=12, mode="sep26", method="fast")
    assert (a.occupancy == b.occupancy).all()


def test_batch_takes_a_bytes_path_and_skips_a_looping_link(tmp_path):
    ds = tmp_path / "ds"
    (ds / "sub").mkdir(parents=True)
    for n in range(2):
        (ds / f"m{n}.obj").write_bytes((REPO / "examples" / "meshes" / "box.obj").read_bytes())
    os.symlink(ds, ds / "sub" / "loop")
    s = topovox.batch(os.fsencode(ds), tmp_path / "out", resolution=8)
    assert (s["done"], s["failed"]) == (2, 0), s
    assert len(s["warnings"]) == 1 and "loop" in s["warnings"][0], s


def test_dask_and_ray_are_reachable_after_import_topovox_without_loading_them():
    import subprocess
    import sys

    code = (
        "import sys, topovox\n"
        "assert 'dask' not in sys.modules and 'ray' not in sys.modules\n"
        "assert callable(topovox.dask.voxelize_paths) and callable(topovox.ray.voxelize_paths)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_readme_dataset_script_runs_as_written(tmp_path):
    """python/README.md's "Whole datasets" script, saved and run as a file
    beside a `meshes/` folder (Dask and Ray start worker processes)."""
    import re
    import shutil
    import subprocess
    import sys

    text = (REPO / "python" / "README.md").read_text(encoding="utf-8")
    scripts = [b for b in re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M) if "__main__" in b]
    assert len(scripts) == 1, "python/README.md should hold one dataset script"
    (tmp_path / "meshes").mkdir()
    for name in ("box.obj", "cow.obj"):
        shutil.copy(REPO / "examples" / "meshes" / name, tmp_path / "meshes" / name)
    (tmp_path / "voxelize_all.py").write_text(scripts[0], encoding="utf-8")
    r = subprocess.run([sys.executable, "voxelize_all.py"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "2 meshes on Dask" in r.stdout and "2 meshes on Ray" in r.stdout, r.stdout
    for out in ("voxels", "voxels-dask", "voxels-ray"):
        assert sorted(p.name for p in (tmp_path / out).glob("*.npy")) == ["box.npy", "cow.npy"]
