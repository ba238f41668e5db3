"""Interoperability check: voxkit's outputs read by real third-party readers.

NumPy reads the .npy files; the `binvox` package from PyPI reads the
.binvox file; both must hold exactly the voxels of voxkit's text list, with
the grid placement reported by `--json`. Prints 'N passed, M failed'.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from binvox import Binvox

VOXKIT = sys.argv[1]
MESHES = Path(sys.argv[2])
passed, failed = 0, 0


def check(name, cond, detail=""):
    global passed, failed
    if cond:
        passed += 1
        print(f"ok   {name}")
    else:
        failed += 1
        print(f"FAIL {name} {detail}")


def voxelize(mesh, out, *extra):
    r = subprocess.run([VOXKIT, "voxelize", str(mesh), "-o", str(out), "--json", *extra], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"voxkit failed: {r.stderr}")
    return json.loads(r.stdout)


def text_voxels(path):
    rows = [l.split() for l in Path(path).read_text().splitlines() if l and not l.startswith("#")]
    return {(int(a), int(b), int(c)) for a, b, c in rows}


with tempfile.TemporaryDirectory() as d:
    d = Path(d)
    for mesh, res in [("cow.obj", 48), ("suzanne.obj", 37), ("stanford-bunny.obj", 64)]:
        m = MESHES / mesh
        summary = voxelize(m, d / "v.npy", "--resolution", str(res))
        voxelize(m, d / "b.npy", "--resolution", str(res), "--format", "npy-bool")
        voxelize(m, d / "v.binvox", "--resolution", str(res))
        voxelize(m, d / "v.txt", "--resolution", str(res))
        want = text_voxels(d / "v.txt")
        nx, ny, nz = summary["dims"]

        a = np.load(d / "v.npy")
        check(f"{mesh} npy shape", a.shape == (nx, ny, nz), a.shape)
        check(f"{mesh} npy dtype uint8", a.dtype == np.uint8, a.dtype)
        check(f"{mesh} npy values 0/1", set(np.unique(a).tolist()) <= {0, 1})
        check(f"{mesh} npy [i,j,k] = text voxels", set(map(tuple, np.argwhere(a).tolist())) == want)
        check(f"{mesh} npy count = summary", int(a.sum()) == summary["voxels"])
        b = np.load(d / "b.npy")
        check(f"{mesh} npy-bool dtype", b.dtype == np.bool_, b.dtype)
        check(f"{mesh} npy-bool equals uint8", np.array_equal(b, a.astype(bool)))

        bv = Binvox.read(str(d / "v.binvox"), "dense")
        side = max(nx, ny, nz)
        check(f"{mesh} binvox dims", list(bv.dims) == [side] * 3, bv.dims)
        check(f"{mesh} binvox translate", np.allclose(bv.translate, summary["origin"], rtol=0, atol=1e-12), bv.translate)
        check(f"{mesh} binvox scale", abs(bv.scale - side * summary["voxel_size"]) < 1e-12, bv.scale)
        data = np.asarray(bv.data)
        check(f"{mesh} binvox voxels (binvox package, xyz order)", np.array_equal(data[:nx, :ny, :nz], a.astype(bool)) and int(data.sum()) == int(a.sum()))

print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
