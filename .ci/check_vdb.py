"""OpenVDB's own reader (Debian's python3-openvdb, module `pyopenvdb`)
reads topovox's .vdb files: every active voxel equals topovox's text list of
the same run, the transform takes index (i, j, k) to the voxel's centre,
and a grid past memory (tiled, --max-memory) has the voxel count topovox
reports. Run with the system Python that has pyopenvdb:
    /usr/bin/python3 .ci/check_vdb.py target/release/topovox ../shared/meshes
Prints 'N passed, M failed'.
"""
import re
import subprocess
import sys
import tempfile
import zlib
from pathlib import Path

import numpy as np
from oracle import Oracle, text_voxels
import pyopenvdb as vdb

TOPOVOX = sys.argv[1]
MESHES = Path(sys.argv[2])
ORACLE = Oracle(TOPOVOX)
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


def vti_arrays(path):
    """The cell arrays of a topovox .vti (appended raw, zlib blocks, UInt64
    headers), read with the standard library: {name: array (nx, ny, nz[, c])}."""
    raw = Path(path).read_bytes()
    head, data = raw.split(b'<AppendedData encoding="raw">', 1)
    data = data[data.index(b"_") + 1:]
    ext = [int(v) for v in re.search(rb'WholeExtent="([^"]+)"', head).group(1).split()]
    nx, ny, nz = ext[1], ext[3], ext[5]
    out = {}
    types = {b"UInt8": np.uint8, b"Int32": np.int32, b"Float32": np.float32}
    for ty, name, comps, off in re.findall(rb'<DataArray type="(\w+)" Name="(\w+)" NumberOfComponents="(\d+)" format="appended" offset="(\d+)"', head):
        at = int(off)
        nb = int.from_bytes(data[at:at + 8], "little")
        sizes = [int.from_bytes(data[at + 8 * (3 + i):at + 8 * (4 + i)], "little") for i in range(nb)]
        at += 8 * (3 + nb)
        buf = b""
        for s in sizes:
            buf += zlib.decompress(data[at:at + s])
            at += s
        a = np.frombuffer(buf, dtype=types[ty])
        c = int(comps)
        # VTK cell order: i fastest.
        a = a.reshape(nz, ny, nx, c).transpose(2, 1, 0, 3)
        out[name.decode()] = a[..., 0] if c == 1 else a
    return out


def grid_values(path, name):
    """Every active voxel of grid `name` and its value, sorted by (i, j, k);
    active tiles expanded."""
    g = vdb.read(str(path), name)
    pts, vals = [], []
    for it in g.citerOnValues():
        lo, hi = np.array(it["min"]), np.array(it["max"])
        box = np.argwhere(np.ones(hi - lo + 1, bool)) + lo
        pts.extend(box)
        vals.extend([it["value"]] * len(box))
    pts = np.array(pts, dtype=np.int64).reshape(-1, 3)
    order = np.lexsort((pts[:, 2], pts[:, 1], pts[:, 0]))
    return g, pts[order], np.array(vals, dtype=np.float64)[order]


def srgb_to_linear(c):
    s = c / 255.0
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


with tempfile.TemporaryDirectory() as d:
    d = Path(d)
    # A grid is a resolution, or voxel sizes per axis (a non-uniform
    # ScaleTranslateMap that OpenVDB gives back per axis).
    for mesh, grid, extra in [
        ("cow.obj", ["--resolution", "48"], []),
        ("suzanne.obj", ["--resolution", "200"], ["--mode", "sep6"]),
        ("stanford-bunny.obj", ["--resolution", "300"], ["--mode", "sep26", "--tile", "64"]),
        ("teapot.obj", ["--resolution", "257"], ["--mode", "bubble", "--seed", "5", "--tile", "128"]),
        ("cow.obj", ["--voxel-size", "0.05,0.05,0.18"], ["--mode", "sep6"]),
        ("suzanne.obj", ["--voxel-size", "0.011,0.03,0.008"], ["--tile", "64"]),
    ]:
        name = f"{mesh} {' '.join(grid + extra)}"
        s = voxelize(MESHES / mesh, d / "v.vdb", *grid, *extra)
        voxelize(MESHES / mesh, d / "v.txt", *grid, *[e for e in extra if e not in ("--tile", "64", "128")])
        g, got = active(d / "v.vdb")
        want = text_voxels(d / "v.txt")
        check(f"{name}: pyopenvdb reads a BoolGrid", isinstance(g, vdb.BoolGrid), type(g))
        check(f"{name}: every active voxel = the dense run's voxels", got.shape == want.shape and (got == want).all(), (got.shape, want.shape))
        check(f"{name}: activeVoxelCount = topovox's count", g.activeVoxelCount() == s["voxels"], (g.activeVoxelCount(), s["voxels"]))
        vs = np.broadcast_to(np.array(s["voxel_size"], float), 3)
        o = np.array(s["origin"])
        centre = np.array(g.transform.indexToWorld((3, 4, 5)))
        check(f"{name}: index (3,4,5) -> that voxel's centre", np.allclose(centre, o + (np.array([3, 4, 5]) + 0.5) * vs, rtol=0, atol=1e-9 * max(1, abs(o).max())), centre)
        check(f"{name}: voxel size per axis", np.allclose(g.transform.voxelSize(), vs, rtol=1e-12, atol=0), g.transform.voxelSize())
        check(f"{name}: metadata dims", tuple(g.metadata["topovox_dims"]) == tuple(s["dims"]), g.metadata)
        # topovox reads its own file back.
        r = subprocess.run([TOPOVOX, "convert", str(d / "v.vdb"), str(d / "back.txt")], capture_output=True, text=True)
        check(f"{name}: topovox convert reads the .vdb", r.returncode == 0 and (text_voxels(d / "back.txt") == want).all(), r.stderr)

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
        check(f"{name}: activeVoxelCount = topovox's count", g.activeVoxelCount() == s["voxels"], (g.activeVoxelCount(), s["voxels"]))

    # --attributes: Cd, normal, coverage and material grids over the same
    # voxels, equal to the .vti arrays of the same run (read here without
    # topovox); a solid's interior is tiles in `voxels`, leaves in the others.
    for mode in ["cover", "solid"]:
        name = f"spot-textured.obj 64 {mode} --attributes"
        s = voxelize(MESHES / "spot-textured.obj", d / "a.vdb", "--resolution", "64", "--mode", mode, "--attributes")
        voxelize(MESHES / "spot-textured.obj", d / "a.vti", "--resolution", "64", "--mode", mode, "--normals")
        v = vti_arrays(d / "a.vti")
        want = np.argwhere(v["occupancy"] > 0)
        names = sorted(m.name for m in vdb.readAllGridMetadata(str(d / "a.vdb")))
        check(f"{name}: five grids", names == ["Cd", "coverage", "material", "normal", "voxels"], names)
        _, occ = active(d / "a.vdb")
        check(f"{name}: voxels = the .vti occupancy", occ.shape == want.shape and (occ == want).all())
        ix = tuple(want.T)
        for grid, kind, expect in [
            ("Cd", vdb.Vec3SGrid, srgb_to_linear(v["colour"][ix].astype(np.float64))),
            ("normal", vdb.Vec3SGrid, v["normal"][ix].astype(np.float64)),
            ("coverage", vdb.FloatGrid, v["coverage"][ix].astype(np.float64)),
            ("material", vdb.FloatGrid, v["material"][ix].astype(np.float64)),
        ]:
            g, pts, vals = grid_values(d / "a.vdb", grid)
            check(f"{name}: {grid} is a {kind.__name__}", isinstance(g, kind), type(g))
            check(f"{name}: {grid}'s active voxels = the voxels", pts.shape == want.shape and (pts == want).all(), (pts.shape, want.shape))
            tol = 1e-6 if grid == "Cd" else 0.0
            check(f"{name}: {grid} values = the .vti's", vals.shape == expect.shape and np.abs(vals - expect).max() <= tol,
                  np.abs(vals - expect).max() if vals.shape == expect.shape else (vals.shape, expect.shape))
        check(f"{name}: colours vary (the texture is carried)", len(np.unique(v["colour"][ix], axis=0)) > 10)

    # A grid past the memory given: tiled automatically, sparse output.
    s = voxelize(MESHES / "stanford-bunny.obj", d / "big.vdb", "--resolution", "4096", "--max-memory", "1G")
    g = vdb.read(str(d / "big.vdb"), "voxels")
    check("bunny at 4096 with --max-memory 1G runs tiled", s["method"] == "tiled" and s["tile"] == 512, s["method"])
    check("bunny at 4096: pyopenvdb's active count = topovox's", g.activeVoxelCount() == s["voxels"], (g.activeVoxelCount(), s["voxels"]))
    r = subprocess.run([TOPOVOX, "voxelize", str(MESHES / "stanford-bunny.obj"), "-o", str(d / "big.npy"), "--resolution", "4096", "--max-memory", "1G"], capture_output=True, text=True)
    check("a dense format past --max-memory is one line naming the sparse formats", r.returncode != 0 and ".vdb" in r.stderr and r.stderr.count("\n") == 1, r.stderr)

ORACLE.finish()
