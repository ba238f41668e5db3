"""Calls per second on small in-memory meshes, as a data loader makes them:
one `topovox.voxelize(mesh, resolution=R)` per mesh (default threads, 1 and
2 threads) against Open3D's `VoxelGrid.create_from_triangle_mesh` loop over
the same meshes (Open3D voxelizes the surface, like `cover`). No file is
read: the meshes are loaded once, then every tool loops over them. Tools
run in alternation, `--repeats` times; the median pass is reported.

    python python/benchmarks/bench_calls.py [MESH_DIR] [--meshes 48]
        [--resolutions 32,64] [--repeats 5] [--json]

The meshes are the files in MESH_DIR (default ../shared/meshes), each
decimated by taking every k-th face until it has at most --faces faces,
then rotated and scaled at random so each call sees a new mesh.
"""

import argparse
import json
import pathlib
import platform
import statistics
import sys
import time

import numpy as np

import topovox


def small_meshes(folder: pathlib.Path, count: int, faces: int, seed: int = 1):
    bases = []
    for p in sorted(folder.glob("*.obj")):
        m = topovox.load_mesh(p)
        f = np.asarray(m.faces)
        bases.append((np.asarray(m.vertices, dtype=np.float64), f[:: max(1, len(f) // faces)]))
    return rotated(bases, count, seed)


def rotated(bases, count: int, seed: int):
    """`count` meshes cycling through `bases`, each rotated and scaled at random."""
    rng = np.random.default_rng(seed)
    out = []
    for n in range(count):
        v, f = bases[n % len(bases)]
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        out.append((v @ q.T * rng.uniform(0.5, 2.0), f))
    return out


def main() -> int:
    here = pathlib.Path(__file__).resolve()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes_dir", nargs="?", type=pathlib.Path, default=here.parents[3] / "shared" / "meshes")
    ap.add_argument("--meshes", type=int, default=48)
    ap.add_argument("--faces", type=int, default=2000)
    ap.add_argument("--resolutions", default="32,64")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    pairs = small_meshes(a.meshes_dir, a.meshes, a.faces)
    ours = [topovox.as_mesh(v, f) for v, f in pairs]
    tools = {}
    for res in [int(r) for r in a.resolutions.split(",")]:
        tools[f"topovox.voxelize, default threads @{res}"] = lambda res=res: [topovox.voxelize(m, resolution=res) for m in ours]
        tools[f"topovox.voxelize, threads=1 @{res}"] = lambda res=res: [topovox.voxelize(m, resolution=res, threads=1) for m in ours]
        tools[f"topovox.voxelize, threads=2 @{res}"] = lambda res=res: [topovox.voxelize(m, resolution=res, threads=2) for m in ours]
    try:
        import open3d as o3d

        o3d_meshes = []
        for v, f in pairs:
            m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f.astype(np.int32)))
            o3d_meshes.append(m)
        for res in [int(r) for r in a.resolutions.split(",")]:

            def o3d_loop(res=res):
                out = []
                for m in o3d_meshes:
                    size = float(np.max(m.get_max_bound() - m.get_min_bound())) / res
                    out.append(o3d.geometry.VoxelGrid.create_from_triangle_mesh(m, voxel_size=size))
                return out

            tools[f"Open3D VoxelGrid loop @{res}"] = o3d_loop
        o3d_version = o3d.__version__
    except ImportError:
        o3d_version = None
        print("Open3D is not installed: its row is left out", file=sys.stderr)
    times = {name: [] for name in tools}
    for _ in range(a.repeats):
        for name, loop in tools.items():
            t = time.perf_counter()
            loop()
            times[name].append(time.perf_counter() - t)
    rows = [{"tool": n, "meshes": len(pairs), "seconds": statistics.median(s), "calls_per_s": len(pairs) / statistics.median(s)} for n, s in times.items()]
    if a.json:
        for r in rows:
            print(json.dumps(r))
        return 0
    faces = statistics.median(len(f) for _, f in pairs)
    print(f"{len(pairs)} meshes, median {faces:.0f} faces, {a.repeats} alternating passes, median pass;"
          f" {platform.processor() or platform.machine()}, Python {platform.python_version()}, Open3D {o3d_version}")
    print()
    print("| tool | calls per second | ms per call |")
    print("|---|---|---|")
    for r in rows:
        print(f"| {r['tool']} | {r['calls_per_s']:.0f} | {1000 * r['seconds'] / r['meshes']:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
