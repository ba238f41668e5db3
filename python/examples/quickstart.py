"""A quick start with topovox and NumPy, type-checked by `mypy --strict`
in the test command and run by the tests: voxelize a mesh, use the grid as
an array, save it, and read it back."""

import os
import sys
import tempfile

import numpy as np

import topovox


def main(mesh_path: str) -> None:
    grid = topovox.voxelize(mesh_path, mode="sep6", resolution=48, fit="cube", pad=1)
    dense = np.asarray(grid)  # (48, 48, 48) bool, element [i, j, k]
    coords = grid.coords()  # (n, 3) int32, C order
    assert dense.sum() == grid.count == len(coords)
    report = grid.check(mesh_path)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "grid.vdb")
        grid.save(path)
        again = topovox.load_voxels(path)
        assert (np.asarray(again) == dense).all()
    print(f"{grid}: 6-separating {report['separating_6']}, {len(coords)} voxels")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "examples/meshes/cow.obj")
