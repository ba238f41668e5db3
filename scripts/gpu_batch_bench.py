"""One gpu-bench.sh row per resolution: COUNT rotated shared meshes voxelized
by `topovox.voxelize_many(method="gpu")` (one upload and one dispatch for
the batch), by one `voxelize(method="gpu")` call per mesh, and by the CPU
(`voxelize_many`, every thread); `cover`, medians of REPEATS.

    python3 scripts/gpu_batch_bench.py MESH_DIR COUNT "64 128" REPEATS
"""

import pathlib
import statistics
import sys
import time

import numpy as np

import topovox


def main() -> None:
    folder, count, resolutions, repeats = pathlib.Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3].split(), int(sys.argv[4])
    rng = np.random.default_rng(1)
    bases = [topovox.load_mesh(p) for p in sorted(folder.glob("*.obj"))]
    meshes = []
    for n in range(count):
        m = bases[n % len(bases)]
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        meshes.append(topovox.as_mesh(np.asarray(m.vertices) @ q.T, np.asarray(m.faces)))
    for res in (int(r) for r in resolutions):
        runs = {
            "GPU, voxelize_many (one dispatch)": lambda: topovox.voxelize_many(meshes, resolution=res, method="gpu"),
            "GPU, one voxelize call per mesh": lambda: [topovox.voxelize(m, resolution=res, fit="cube", method="gpu") for m in meshes],
            "CPU, voxelize_many": lambda: topovox.voxelize_many(meshes, resolution=res),
        }
        times = {k: [] for k in runs}
        for _ in range(repeats):
            for k, f in runs.items():
                t = time.perf_counter()
                f()
                times[k].append(time.perf_counter() - t)
        for k, v in times.items():
            ms = statistics.median(v) * 1e3
            print(f"| {count} meshes cover {res} | {k} | {ms:.1f} | {count / ms * 1e3:.0f} meshes/s |")


if __name__ == "__main__":
    main()
