"""Meshes per second on a dataset (made by make_dataset.py), at several
resolutions, in one run: `topovox batch` on 1 and 2 jobs, `topovox.voxelize`
from Python, a loop over the CLI, trimesh's `voxelized` and Open3D's
`VoxelGrid.create_from_triangle_mesh`; and the Python call's overhead over
the Rust voxelization. Each line includes reading the mesh file.

    python python/benchmarks/bench_dataset.py DATASET [--resolutions 32,64,128]
        [--subset 100] [--topovox target/release/topovox]

Prints a Markdown table (and JSON lines with --json).
"""

import argparse
import json
import os
import pathlib
import platform
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import topovox


def timed(f):
    t = time.perf_counter()
    r = f()
    return time.perf_counter() - t, r


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("dataset", type=pathlib.Path)
    ap.add_argument("--resolutions", default="32,64,128")
    ap.add_argument("--subset", type=int, default=100, help="meshes for the slow tools (CLI loop, trimesh, Open3D)")
    ap.add_argument("--trimesh-subset", type=int, default=20)
    ap.add_argument("--topovox", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[2] / "target" / "release" / "topovox")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    files = sorted(a.dataset.glob("*.stl"))
    subset = files[: a.subset]
    rows = []
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="topovox-bench-"))

    def row(tool, res, n, seconds, note=""):
        rows.append({"tool": tool, "resolution": res, "meshes": n, "seconds": seconds, "meshes_per_s": n / seconds, "note": note})

    try:
        for res in [int(r) for r in a.resolutions.split(",")]:
            # topovox batch, 1 and 2 jobs (fresh output folder each).
            for jobs in (1, 2):
                out = tmp / f"batch-{res}-{jobs}"
                s, _ = timed(lambda: subprocess.run([str(a.topovox), "batch", str(a.dataset), "-o", str(out), "--resolution", str(res),
                                                     "--jobs", str(jobs), "--quiet"], check=True))
                row(f"topovox batch --jobs {jobs}", res, len(files), s)
                shutil.rmtree(out)
            # topovox.voxelize from Python: load + voxelize, all cores and one thread.
            for threads in (None, 1):
                calls = rust = 0.0

                def run():
                    nonlocal calls, rust
                    for f in files:
                        m = topovox.load_mesh(f)
                        t = time.perf_counter()
                        g = topovox.voxelize(m, resolution=res, threads=threads)
                        calls += time.perf_counter() - t
                        rust += g.facts["voxelize_s"]

                s, _ = timed(run)
                note = f"voxelize calls {calls:.3f} s vs Rust voxelization {rust:.3f} s: +{(calls / rust - 1) * 100:.1f} %"
                row(f"topovox.voxelize (threads={threads or 'all'})", res, len(files), s, note)
            # A loop over the CLI.
            out = tmp / "cli.npy"
            s, _ = timed(lambda: [subprocess.run([str(a.topovox), "voxelize", str(f), "-o", str(out), "--resolution", str(res), "--quiet"],
                                                 check=True) for f in subset])
            row("CLI loop (topovox voxelize per file)", res, len(subset), s)
            # trimesh: voxelized(pitch) with the same voxel size.
            try:
                import trimesh

                def tm():
                    for f in files[: a.trimesh_subset]:
                        mesh = trimesh.load(f, force="mesh")
                        mesh.voxelized(pitch=float(np.max(mesh.extents)) / res)

                s, _ = timed(tm)
                row("trimesh voxelized", res, a.trimesh_subset, s)
            except ImportError:
                pass
            # Open3D.
            try:
                import open3d as o3d

                def o3():
                    for f in subset:
                        mesh = o3d.io.read_triangle_mesh(str(f))
                        ext = mesh.get_max_bound() - mesh.get_min_bound()
                        o3d.geometry.VoxelGrid.create_from_triangle_mesh(mesh, voxel_size=float(np.max(ext)) / res)

                s, _ = timed(o3)
                row("Open3D VoxelGrid.create_from_triangle_mesh", res, len(subset), s)
            except ImportError:
                pass
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if a.json:
        for r in rows:
            print(json.dumps(r))
        return 0
    print(f"dataset: {a.dataset} ({len(files)} meshes); {os.cpu_count()} CPUs; {platform.platform()}; topovox {topovox.__version__}\n")
    print("| tool | resolution | meshes | seconds | meshes/s | note |\n|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['tool']} | {r['resolution']} | {r['meshes']} | {r['seconds']:.2f} | {r['meshes_per_s']:.1f} | {r['note']} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
