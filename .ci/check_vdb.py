"""OpenVDB's own reader (Debian's python3-openvdb, module `pyopenvdb`)
reads voxkit's .vdb files: every active voxel equals voxkit's text list of
the same run, the transform takes index (i, j, k) to the voxel's centre,
and a grid past memory (tiled, --max-memory) has the voxel count voxkit
reports. Run with the system Python that has pyopenvdb:
    /usr/bin/python3 .ci/check_vdb.py target/release/voxkit ../shared/meshes
Prints 'N passed, M failed'.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from oracle import Oracle, text_voxels
import pyopenvdb as vdb

VOXKIT = sys.argv[1]
MESHES = Path(sys.argv[2])
ORACLE = Oracle(VOXKIT)
check, voxelize = ORACLE.check, ORACLE.voxelize


def active(path):
    g = vdb.read(str(path), "voxels")
    pts = []
    for it in g.citerOnValues():
        lo, hi = np.array(it["min"]), np.array(it["max"])
        if (lo == hi).all():
            pts.append(lo)
        else:  # an active tile
            pts.extend(np.argwhere(np.ones(hi - lo + 1, bool)) + lo)
    pts = np.array(pts, dtype=np.int64).reshape(-1, 3)
    return g, pts[np.lexsort((pts[:, 2], pts[:, 1], pts[:, 0]))]


with tempfile.TemporaryDirectory() as d:
    d = Path(d)
    for mesh, res, extra in [
        ("cow.obj", 48, []),
        ("suzanne.obj", 200, ["--mode", "sep6"]),
        ("stanford-bunny.obj", 300, ["--mode", "sep26", "--tile", "64"]),
        ("teapot.obj", 257, ["--mode", "bubble", "--seed", "5", "--tile", "128"]),
    ]:
        name = f"{mesh} {' '.join([str(res)] + extra)}"
        s = voxelize(MESHES / mesh, d / "v.vdb", "--resolution", str(res), *extra)
        voxelize(MESHES / mesh, d / "v.txt", "--resolution", str(res), *[e for e in extra if e not in ("--tile", "64", "128")])
        g, got = active(d / "v.vdb")
        want = text_voxels(d / "v.txt")
        check(f"{name}: pyopenvdb reads a BoolGrid", isinstance(g, vdb.BoolGrid), type(g))
        check(f"{name}: every active voxel = the dense run's voxels", got.shape == want.shape and (got == want).all(), (got.shape, want.shape))
        check(f"{name}: activeVoxelCount = voxkit's count", g.activeVoxelCount() == s["voxels"], (g.activeVoxelCount(), s["voxels"]))
        vs = s["voxel_size"]
        o = np.array(s["origin"])
        centre = np.array(g.transform.indexToWorld((3, 4, 5)))
        check(f"{name}: index (3,4,5) -> that voxel's centre", np.allclose(centre, o + (np.array([3, 4, 5]) + 0.5) * vs, rtol=0, atol=1e-9 * max(1, abs(o).max())), centre)
        check(f"{name}: voxel size", abs(g.transform.voxelSize()[0] - vs) <= 1e-12 * vs)
        check(f"{name}: metadata dims", tuple(g.metadata["voxkit_dims"]) == tuple(s["dims"]), g.metadata)
        # voxkit reads its own file back.
        r = subprocess.run([VOXKIT, "convert", str(d / "v.vdb"), str(d / "back.txt")], capture_output=True, text=True)
        check(f"{name}: voxkit convert reads the .vdb", r.returncode == 0 and (text_voxels(d / "back.txt") == want).all(), r.stderr)

    # Sparse solids: interiors written as active tiles (8³, and 128³ where
    # a whole 16³ node is inside), equal to the dense run's .npy.
    cube = d / "cube.obj"
    cube.write_text("".join(f"v {x} {y} {z}\n" for z in (0, 1) for y in (0, 1) for x in (0, 1))
                    + "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n")
    for mesh, res, extra in [
        (cube, 160, ["--mode", "solid"]),
        (MESHES / "stanford-bunny.obj", 150, ["--mode", "solid", "--method", "parity"]),
        (MESHES / "teapot.obj", 130, ["--mode", "solid+surface", "--method", "parity", "--surface", "sep26"]),
    ]:
        name = f"{mesh.name} {res} {' '.join(extra)} tiled"
        s = voxelize(mesh, d / "s.vdb", "--resolution", str(res), "--tile", "64", *extra)
        voxelize(mesh, d / "s.npy", "--resolution", str(res), *extra)
        g, got = active(d / "s.vdb")
        want = np.argwhere(np.load(d / "s.npy") > 0)
        tiles = sum(1 for it in g.citerOnValues() if tuple(it["min"]) != tuple(it["max"]))
        check(f"{name}: runs tiled with full bricks", s["tile"] == 64 and s["solid"]["full_bricks"] > 0, s)
        check(f"{name}: the interior is active tiles", tiles > 0, tiles)
        check(f"{name}: every active voxel = the dense run's .npy", got.shape == want.shape and (got == want).all(), (got.shape, want.shape))
        check(f"{name}: activeVoxelCount = voxkit's count", g.activeVoxelCount() == s["voxels"], (g.activeVoxelCount(), s["voxels"]))

    # A grid past the memory given: tiled automatically, sparse output.
    s = voxelize(MESHES / "stanford-bunny.obj", d / "big.vdb", "--resolution", "4096", "--max-memory", "1G")
    g = vdb.read(str(d / "big.vdb"), "voxels")
    check("bunny at 4096 with --max-memory 1G runs tiled", s["method"] == "tiled" and s["tile"] == 512, s["method"])
    check("bunny at 4096: pyopenvdb's active count = voxkit's", g.activeVoxelCount() == s["voxels"], (g.activeVoxelCount(), s["voxels"]))
    r = subprocess.run([VOXKIT, "voxelize", str(MESHES / "stanford-bunny.obj"), "-o", str(d / "big.npy"), "--resolution", "4096", "--max-memory", "1G"], capture_output=True, text=True)
    check("a dense format past --max-memory is one line naming the sparse formats", r.returncode != 0 and ".vdb" in r.stderr and r.stderr.count("\n") == 1, r.stderr)

ORACLE.finish()
