"""Meshes per second for training batches (issue 57): `voxelize_many` on
small in-memory meshes against a Python loop over `topovox.voxelize` and
loops over Open3D's and trimesh's voxelizers on the same meshes.

    python python/benchmarks/bench_many.py [MESH_DIR] [--meshes 1000]
        [--resolutions 32,64] [--repeats 3] [--trimesh 100]

The meshes: each file in MESH_DIR (default ../shared/meshes) decimated by
Open3D's quadric decimation to a face count drawn from 2,000-10,000, then
rotated and scaled at random, `--meshes` of them, all held in memory
(converted once to each tool's type). 2 threads: `threads=2` for topovox,
`OMP_NUM_THREADS=2` for Open3D. `fit="cube"`. Rows run in alternation,
`--repeats` times; the median pass is reported. trimesh's loop is slow and
runs on the first `--trimesh` meshes only (its rate is per mesh all the
same). Open3D and trimesh voxelize the surface (as `cover`).
"""

import argparse
import os
import pathlib
import platform
import statistics
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "2")

import numpy as np

import topovox

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from bench_calls import rotated  # noqa: E402  (the same random rotations)


def decimated(folder: pathlib.Path, seed: int):
    import open3d as o3d

    rng = np.random.default_rng(seed)
    out = []
    for p in sorted(folder.glob("*.obj")):
        m = topovox.load_mesh(p)
        o = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.asarray(m.vertices)), o3d.utility.Vector3iVector(np.asarray(m.faces, dtype=np.int32)))
        target = int(rng.integers(2000, 10001))
        if len(m.faces) > target:
            o = o.simplify_quadric_decimation(target)
        out.append((np.asarray(o.vertices), np.asarray(o.triangles, dtype=np.int64)))
    return out


def main() -> int:
    here = pathlib.Path(__file__).resolve()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes_dir", nargs="?", type=pathlib.Path, default=here.parents[3] / "shared" / "meshes")
    ap.add_argument("--meshes", type=int, default=1000)
    ap.add_argument("--resolutions", default="32,64")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--trimesh", type=int, default=100)
    a = ap.parse_args()
    import open3d as o3d
    import trimesh

    pairs = rotated(decimated(a.meshes_dir, 1), a.meshes, 2)
    ours = [topovox.as_mesh(v, f) for v, f in pairs]
    o3d_meshes = [o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f.astype(np.int32))) for v, f in pairs]
    tri = [trimesh.Trimesh(v, f, process=False) for v, f in pairs[: a.trimesh]]
    tools = {}
    for res in [int(r) for r in a.resolutions.split(",")]:
        rows = [("cover", ("occupancy",)), ("cover", ("occupancy", "normal")), ("solid", ("occupancy",))]
        # The sdf column at 32 only: at 64 it is most of the run's time.
        for mode, feats in rows + ([("solid", ("occupancy", "sdf"))] if res <= 32 else []):
            name = f"voxelize_many {mode}, {'+'.join(feats)} @{res}"
            tools[name] = (len(ours), lambda res=res, mode=mode, feats=feats: topovox.voxelize_many(ours, resolution=res, mode=mode, features=feats, threads=2))
        tools[f"loop over voxelize(threads=1) cover @{res}"] = (len(ours), lambda res=res: [topovox.voxelize(m, resolution=res, fit="cube", threads=1) for m in ours])

        def o3d_loop(res=res):
            out = []
            for m in o3d_meshes:
                size = float(np.max(m.get_max_bound() - m.get_min_bound())) / res
                out.append(o3d.geometry.VoxelGrid.create_from_triangle_mesh(m, voxel_size=size))
            return out

        tools[f"Open3D VoxelGrid loop @{res}"] = (len(o3d_meshes), o3d_loop)
        tools[f"trimesh voxelized loop @{res}"] = (len(tri), lambda res=res: [m.voxelized(float(m.extents.max()) / res) for m in tri])
    times = {name: [] for name in tools}
    for _ in range(a.repeats):
        for name, (_, loop) in tools.items():
            t = time.perf_counter()
            loop()
            times[name].append(time.perf_counter() - t)
    faces = statistics.median(len(f) for _, f in pairs)
    print(f"{len(pairs)} meshes (median {faces:.0f} faces), {a.repeats} alternating passes, median pass; "
          f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"Open3D {o3d.__version__}, trimesh {trimesh.__version__}")
    print()
    print("| tool | meshes | meshes per second | ms per mesh |")
    print("|---|---|---|---|")
    for name, (n, _) in tools.items():
        s = statistics.median(times[name])
        print(f"| {name} | {n} | {n / s:.0f} | {1000 * s / n:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
