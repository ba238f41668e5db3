"""Distance fields read by their home readers (issue 42).

    /usr/bin/python3 .ci/check_sdf.py target/release/topovox ../shared/meshes vdb
    python3 .ci/check_sdf.py target/release/topovox ../shared/meshes arrays

`vdb` (the system Python, with Debian's pyopenvdb): OpenVDB reads
`topovox sdf`'s .vdb as a level set named `surface` with background W·h,
the voxel size and index-to-world transform of `voxelize`'s .vdb, the band
as its active voxels, and every value (active, inactive, tiles) equal to
the .npy of the same run; `--unsigned` is class `unknown`.
`arrays` (NumPy, zarr, VTK): the .zarr and the .vti hold the .npy's values;
the .npy is negative exactly where `voxelize --mode solid`'s .npy is set.
Prints 'N passed, M failed'.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from oracle import Oracle

TOPOVOX, MESHES, PART = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
ORACLE = Oracle(TOPOVOX)
check = ORACLE.check


def sdf(mesh, out, *extra):
    r = subprocess.run([TOPOVOX, "sdf", str(mesh), "-o", str(out), "--json", *extra], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"topovox sdf failed: {r.stderr}")
    return json.loads(r.stdout)


# Each case: mesh, grid options (a resolution, or voxel sizes per axis), extra options.
CASES = [
    ("cow.obj", ["--resolution", "64"], []),
    ("stanford-bunny.obj", ["--resolution", "96"], []),
    ("teapot.obj", ["--resolution", "48"], ["--sign", "winding"]),
    ("suzanne.obj", ["--resolution", "40"], ["--unsigned"]),
    ("cow.obj", ["--voxel-size", "0.05,0.08,0.2"], []),
]

with tempfile.TemporaryDirectory() as d:
    d = Path(d)
    for mesh, res, extra in CASES:
        m = MESHES / mesh
        s = sdf(m, d / "f.npy", *res, *extra)
        vs = np.broadcast_to(np.array(s["voxel_size"], float), 3)
        a = np.load(d / "f.npy")
        nx, ny, nz = s["dims"]
        bg = np.float32(s["background"])
        check(f"{mesh}: npy float32 (nx, ny, nz)", a.dtype == np.float32 and a.shape == (nx, ny, nz), (a.dtype, a.shape))
        check(f"{mesh}: band = |d| < background, count as reported", int((np.abs(a) < bg).sum()) == s["stored_voxels"])
        if PART == "vdb":
            import pyopenvdb as vdb

            sdf(m, d / "f.vdb", *res, *extra)
            g = vdb.read(str(d / "f.vdb"), "surface")
            cls = "unknown" if "--unsigned" in extra else "level set"
            check(f"{mesh}: class {cls}, background W·h", g.gridClass == cls and np.float32(g.background) == bg, (g.gridClass, g.background))
            check(f"{mesh}: voxel size per axis", np.allclose(g.transform.voxelSize(), vs, rtol=1e-12))
            o = np.array(s["origin"]) + 0.5 * vs
            w = g.transform.indexToWorld((3, 5, 7))
            check(f"{mesh}: index (i, j, k) at the voxel's centre", np.allclose(w, o + np.array([3, 5, 7]) * vs, rtol=0, atol=1e-9), w)
            check(f"{mesh}: active voxels = the band", g.activeVoxelCount() == s["stored_voxels"], (g.activeVoxelCount(), s["stored_voxels"]))
            dense = np.zeros((nx, ny, nz), np.float32)
            g.copyToArray(dense, ijk=(0, 0, 0))
            check(f"{mesh}: every value (active, inactive, tiles) = the .npy", np.array_equal(dense, a), np.abs(dense - a).max())
            act = np.zeros((nx, ny, nz), bool)
            for it in g.citerOnValues():
                lo, hi = np.array(it["min"]), np.array(it["max"])
                act[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1, lo[2]:hi[2] + 1] = True
            check(f"{mesh}: active exactly where |d| < background", np.array_equal(act, np.abs(a) < bg))
        else:
            import vtk
            import zarr
            from vtk.util.numpy_support import vtk_to_numpy

            sdf(m, d / "f.zarr", *res, *extra)
            z = zarr.open_array(str(d / "f.zarr"), mode="r")
            check(f"{mesh}: zarr float32 = the .npy", z.dtype == np.float32 and np.array_equal(z[:], a))
            check(f"{mesh}: zarr attributes record the voxel size", z.attrs["topovox"]["voxel_size"] == s["voxel_size"], dict(z.attrs))
            sdf(m, d / "f.vti", *res, *extra)
            r = vtk.vtkXMLImageDataReader()
            r.SetFileName(str(d / "f.vti"))
            r.Update()
            img = r.GetOutput()
            v = vtk_to_numpy(img.GetCellData().GetArray("distance")).reshape(nz, ny, nx).transpose(2, 1, 0)
            check(f"{mesh}: vti 'distance' = the .npy, spacing the voxel size", np.array_equal(v, a) and np.allclose(img.GetSpacing(), vs))
            if "--unsigned" in extra:
                check(f"{mesh}: unsigned: no negative value", (a >= 0).all())
            else:
                method = "winding" if "winding" in extra else "auto"
                ORACLE.voxelize(m, d / "s.npy", *res, "--mode", "solid", "--method", method)
                solid = np.load(d / "s.npy") > 0
                check(f"{mesh}: d < 0 exactly on voxelize --mode solid's voxels", np.array_equal(a < 0, solid), int((a < 0).sum() - solid.sum()))
    if PART == "arrays":
        # --band all: every voxel its distance; zarr read lazily by Dask.
        s = sdf(MESHES / "cow.obj", d / "all.npy", "--resolution", "32", "--band", "all")
        a = np.load(d / "all.npy")
        check("band all: every voxel stored", s["stored_voxels"] == a.size and (np.abs(a) <= np.float32(s["background"])).all())
ORACLE.finish()
