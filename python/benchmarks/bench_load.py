"""Loading meshes from files: `topovox.load_mesh` against Open3D's
`io.read_triangle_mesh` and trimesh's `load(..., process=False)` on the
same files (issue 69).

    python python/benchmarks/bench_load.py [MESH] [--sizes 1k,5k,69k,278k,1.1M]
        [--formats ply,ply-ascii,stl,obj,off,glb] [--repeats 15] [--json]
    python python/benchmarks/bench_load.py --many 200 [--resolution 32]

`--many N` times a dataset instead: N small binary PLY files (the shared
meshes, every k-th face to at most 5,000 faces, rotated at random, as
bench_calls.py makes them), voxelized from their paths by one
`topovox.voxelize_many(paths)` against Open3D's loop of
`read_triangle_mesh` and `VoxelGrid.create_from_triangle_mesh` over the
same files, and against `voxelize_many` on the meshes already in memory.
2 threads for both (`threads=2`, `OMP_NUM_THREADS=2`), `fit="cube"`.

The files are written once into a temporary folder by trimesh from MESH
(default: the shared Stanford bunny): its first 1 k and 5 k faces, the
whole bunny (69 k), and 4 and 16 shifted copies of it (278 k, 1.1 M).
Each tool loads each file in turn, in alternation, `--repeats` times, in
this one process; the median per tool is reported. Every tool gives back
a mesh ready to use: topovox a `Mesh` (validated, bounds and degenerate
count known), Open3D a `TriangleMesh`, trimesh a `Trimesh` (unprocessed).
"""

import argparse
import json
import os
import pathlib
import platform
import statistics
import sys
import tempfile
import time
from typing import Any, Dict, List

os.environ.setdefault("OMP_NUM_THREADS", "2")
# OpenMP threads left spinning after Open3D's call would take the cores
# from the next tool in the alternation.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numpy as np

import topovox

SIZES = {"1k": 1_000, "5k": 5_000, "69k": 0, "278k": 4, "1.1M": 16}
# Format name -> (suffix, trimesh export keyword arguments).
FORMATS = {
    "ply": (".ply", {"encoding": "binary"}),
    "ply-ascii": (".ply", {"encoding": "ascii"}),
    "stl": (".stl", {}),
    "obj": (".obj", {"include_normals": False, "include_texture": False}),
    "off": (".off", {}),
    "glb": (".glb", {}),
}


def meshes(source: pathlib.Path, sizes):
    import trimesh

    base = trimesh.load(source, process=False, force="mesh")
    v, f = np.asarray(base.vertices), np.asarray(base.faces)
    span = float(np.ptp(v, axis=0).max())
    for name in sizes:
        n = SIZES[name]
        if name in ("1k", "5k"):
            used = np.unique(f[:n])
            remap = np.full(len(v), -1)
            remap[used] = np.arange(len(used))
            yield name, trimesh.Trimesh(v[used], remap[f[:n]], process=False)
        elif n == 0:
            yield name, trimesh.Trimesh(v, f, process=False)
        else:
            vs = [v + [1.1 * span * k, 0, 0] for k in range(n)]
            fs = [f + len(v) * k for k in range(n)]
            yield name, trimesh.Trimesh(np.vstack(vs), np.vstack(fs), process=False)


def tools():
    out = {"topovox": lambda p: topovox.load_mesh(p)}
    try:
        import open3d as o3d

        out["open3d"] = lambda p: o3d.io.read_triangle_mesh(str(p))
    except ImportError:
        print("open3d is not installed: its column is left out", file=sys.stderr)
    import trimesh

    out["trimesh"] = lambda p: trimesh.load(p, process=False, force="mesh")
    return out


def faces_of(tool: str, m) -> int:
    if tool == "open3d":
        return len(m.triangles)
    return len(m.faces)


def many(folder: pathlib.Path, count: int, resolution: int, repeats: int) -> Dict[str, Any]:
    """Meshes per second from files: voxelize_many(paths) against Open3D's loop."""
    import trimesh

    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from bench_calls import small_meshes

    pairs = small_meshes(folder, count, 5000)
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for n, (v, f) in enumerate(pairs):
            paths.append(os.path.join(tmp, f"{n:05d}.ply"))
            trimesh.Trimesh(v, f, process=False).export(paths[-1], encoding="binary")
        in_memory = [topovox.as_mesh(v, f) for v, f in pairs]
        tools = {
            "topovox voxelize_many(paths)": lambda: topovox.voxelize_many(paths, resolution=resolution, fit="cube", threads=2),
            "topovox voxelize_many(meshes in memory)": lambda: topovox.voxelize_many(in_memory, resolution=resolution, fit="cube", threads=2),
        }
        try:
            import open3d as o3d

            def o3d_loop():
                for p in paths:
                    m = o3d.io.read_triangle_mesh(p)
                    size = float(np.max(m.get_max_bound() - m.get_min_bound())) / resolution
                    o3d.geometry.VoxelGrid.create_from_triangle_mesh(m, voxel_size=size)

            tools["Open3D read + VoxelGrid loop"] = o3d_loop
        except ImportError:
            print("open3d is not installed: its row is left out", file=sys.stderr)
        times: Dict[str, List[float]] = {t: [] for t in tools}
        for _ in range(repeats):
            for t, run in tools.items():
                start = time.perf_counter()
                run()
                times[t].append(time.perf_counter() - start)
    rows = {t: count / statistics.median(s) for t, s in times.items()}
    for t, rate in rows.items():
        print(f"{t:>42}: {rate:8.0f} meshes/s at {resolution}", flush=True)
    return rows


def main() -> int:
    here = pathlib.Path(__file__).resolve()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs="?", type=pathlib.Path, default=here.parents[3] / "shared" / "meshes" / "stanford-bunny.obj")
    ap.add_argument("--sizes", default="1k,5k,69k,278k,1.1M")
    ap.add_argument("--formats", default=",".join(FORMATS))
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--many", type=int, default=0, help="time a dataset of this many small files instead")
    ap.add_argument("--resolution", type=int, default=32)
    a = ap.parse_args()
    if a.many:
        rows = many(a.mesh.parent, a.many, a.resolution, a.repeats)
        if a.json:
            print(json.dumps({"machine": platform.platform(), "meshes_per_second": rows}, indent=1))
        return 0
    run = tools()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        files = []
        for size, m in meshes(a.mesh, a.sizes.split(",")):
            for fmt in a.formats.split(","):
                suffix, kw = FORMATS[fmt]
                path = pathlib.Path(tmp) / f"{size}-{fmt}{suffix}"
                m.export(path, **kw)
                files.append((size, fmt, path, len(m.faces)))
        for size, fmt, path, faces in files:
            times = {t: [] for t in run}
            for t, load in run.items():
                got = faces_of(t, load(path))  # warm the file cache and the imports
                if got != faces:
                    print(f"{t} read {got} faces of {faces} from {path.name}", file=sys.stderr)
            for _ in range(a.repeats):
                for t, load in run.items():
                    start = time.perf_counter()
                    load(path)
                    times[t].append(time.perf_counter() - start)
            row = {"file": f"{size} {fmt}", "faces": faces, "bytes": path.stat().st_size}
            row.update({t: statistics.median(s) for t, s in times.items()})
            rows.append(row)
            if not a.json:
                cells = "  ".join(f"{t} {row[t] * 1e3:8.2f} ms" for t in run)
                ratios = "  ".join(f"{t}/topovox {row[t] / row['topovox']:.2f}x" for t in run if t != "topovox")
                print(f"{row['file']:>16}  {cells}  {ratios}", flush=True)
    if a.json:
        print(json.dumps({"machine": platform.platform(), "processor": platform.processor(), "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
