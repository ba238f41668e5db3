"""Distance fields against OpenVDB and libigl, side by side (issue 42).

    python3 python/benchmarks/bench_sdf.py drive TOPOVOX MESHES [REPEATS]

Runs, in alternation and `REPEATS` times each (default 3), reporting medians:
- narrow band (half width 3): `topovox sdf MESH -o x.vdb --threads 2`
  (the whole command: loading, sign, distances, writing) against OpenVDB's
  `meshToLevelSet` (`pyopenvdb.FloatGrid.createLevelSetFromPolygons`,
  conversion only, the mesh already in arrays; TBB on the same 2 cores),
  on the bunny and on the bunny subdivided once (277 804 triangles) at
  256, 512 and 1024; on the voxels both store, the largest difference of
  the distances (in voxels) and how many signs differ (OpenVDB decides
  inside by flood fill, which differs from the solid's rule on open meshes);
- every voxel (`--band all`) at 64 and 128 against libigl's
  `signed_distance` (winding-number sign), both including reading the OBJ.
OpenVDB runs in Debian's Python (`/usr/bin/python3`, python3-openvdb) and
libigl in `$IGL_PYTHON` (a Python with `pip install libigl`), each in a
process of its own: `openvdb` and `igl` are this script's other modes.
"""
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def load_obj(path):
    v, f = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) for t in line.split()[1:]]
            idx = [i - 1 if i > 0 else len(v) + i for i in idx]
            f.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    return np.array(v, dtype=np.float64), np.array(f, dtype=np.int64)


def subdivide(src, dst):
    """Each triangle into four at its edges' midpoints."""
    v, f = load_obj(src)
    verts, mids = [tuple(p) for p in v], {}

    def mid(a, b):
        key = (min(a, b), max(a, b))
        if key not in mids:
            mids[key] = len(verts)
            verts.append(tuple((v[a] + v[b]) / 2))
        return mids[key]

    faces = []
    for a, b, c in f:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        faces += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    with open(dst, "w") as out:
        out.writelines(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in verts)
        out.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces)
    return len(faces)


def openvdb_mode(mesh, facts_path, ours):
    """Times meshToLevelSet on topovox's grid (same voxel size, index (i, j, k)
    at the same centre) and compares with topovox's .vdb `ours`."""
    import pyopenvdb as vdb

    facts = json.loads(Path(facts_path).read_text())
    v, f = load_obj(mesh)
    h = facts["voxel_size"]
    t = np.array(facts["origin"]) + 0.5 * h
    xf = vdb.createLinearTransform([[h, 0, 0, 0], [0, h, 0, 0], [0, 0, h, 0], [t[0], t[1], t[2], 1]])
    start = time.perf_counter()
    g = vdb.FloatGrid.createLevelSetFromPolygons(v.astype(np.float32), triangles=f.astype(np.int32), transform=xf, halfWidth=3.0)
    seconds = time.perf_counter() - start
    mine = vdb.read(ours, "surface").getConstAccessor()
    worst, both, signs = 0.0, 0, 0
    for it in g.citerOnValues():
        if it["min"] != it["max"]:
            continue
        value, on = mine.probeValue(it["min"])
        if on:
            both += 1
            worst = max(worst, abs(abs(value) - abs(it["value"])) / h)
            signs += (value < 0) != (it["value"] < 0)
    print(json.dumps({"seconds": seconds, "active": g.activeVoxelCount(), "both": both, "max_diff_voxels": worst, "signs_differ": signs}))


def igl_mode(mesh, res):
    """libigl's signed_distance at every voxel centre of topovox's grid for
    `--resolution res`, including reading the OBJ."""
    start = time.perf_counter()
    import igl

    v, f = load_obj(mesh)
    lo, ext = v.min(0), v.max(0) - v.min(0)
    h = ext.max() / res
    dims = np.maximum(np.ceil(ext / h).astype(int), 1)
    axes = [lo[a] + (np.arange(dims[a]) + 0.5) * h for a in range(3)]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    s = igl.signed_distance(points, v, f)[0]
    print(json.dumps({"seconds": time.perf_counter() - start, "voxels": int(s.size)}))


def run(cmd):
    start = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{cmd[0]} failed: {out.stderr}")
    return time.perf_counter() - start, out.stdout


def drive(topovox, meshes, repeats):
    import os

    me = str(Path(__file__).resolve())
    igl_python = os.environ.get("IGL_PYTHON")
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        bunny = str(Path(meshes) / "stanford-bunny.obj")
        big = str(d / "bunny-x4.obj")
        n = subdivide(bunny, big)
        print("## Narrow band, half width 3: topovox sdf (whole command, 2 threads) vs OpenVDB meshToLevelSet (conversion only)\n")
        print("| mesh | resolution | topovox | OpenVDB | ratio | voxels both store | largest difference of \\|d\\| (voxels) | signs that differ |")
        print("|---|---|---|---|---|---|---|---|")
        for mesh, label in [(bunny, "bunny (69 451 triangles)"), (big, f"bunny subdivided ({n} triangles)")]:
            for res in (256, 512, 1024):
                ours, theirs, o = [], [], {}
                for _ in range(repeats):
                    t, out = run([topovox, "sdf", mesh, "-o", str(d / "x.vdb"), "--resolution", str(res), "--threads", "2", "--json"])
                    ours.append(t)
                    (d / "facts.json").write_text(out)
                    _, out = run(["/usr/bin/python3", me, "openvdb", mesh, str(d / "facts.json"), str(d / "x.vdb")])
                    o = json.loads(out)
                    theirs.append(o["seconds"])
                a, b = statistics.median(ours), statistics.median(theirs)
                print(f"| {label} | {res} | {a:.2f} s | {b:.2f} s | {b / a:.1f}× | {o['both']} | {o['max_diff_voxels']:.2e} | {o['signs_differ']} |", flush=True)
        if not igl_python:
            print("\n(no $IGL_PYTHON: the libigl table is left out)")
            return
        print("\n## Every voxel (--band all), loading included: topovox sdf (2 threads) vs libigl signed_distance\n")
        print("| resolution | topovox | libigl | ratio |")
        print("|---|---|---|---|")
        for res in (64, 128):
            ours, theirs = [], []
            for _ in range(repeats):
                t, _ = run([topovox, "sdf", bunny, "-o", str(d / "a.npy"), "--resolution", str(res), "--band", "all", "--threads", "2"])
                ours.append(t)
                t, _ = run([igl_python, me, "igl", bunny, str(res)])
                theirs.append(t)
            a, b = statistics.median(ours), statistics.median(theirs)
            print(f"| bunny at {res} | {a:.2f} s | {b:.2f} s | {b / a:.1f}× |", flush=True)


if __name__ == "__main__":
    mode = sys.argv[1]
    if mode == "openvdb":
        openvdb_mode(*sys.argv[2:5])
    elif mode == "igl":
        igl_mode(sys.argv[2], int(sys.argv[3]))
    else:
        drive(sys.argv[2], sys.argv[3], int(sys.argv[4]) if len(sys.argv) > 4 else 3)
