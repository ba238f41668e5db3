"""Point queries against Open3D, libigl and point-cloud-utils, side by side (issue 56).

    python python/benchmarks/bench_query.py MESH [POINTS] [REPEATS]

`POINTS` (default 1 000 000) uniform in the mesh's box grown by 10 %, 2
threads for every library (`threads=2`, `OMP_NUM_THREADS=2`), the query
structures built once (build times reported apart). In alternation,
`REPEATS` times (default 3), medians:
- topovox `Query.distance` (signed, exact), `Query.contains` (the solid's
  rule: winding number on an open mesh, parity on a closed one) and
  `contains` with `sign="parity"`;
- Open3D `RaycastingScene.compute_signed_distance` and `compute_occupancy`
  (ray parity);
- libigl `signed_distance` (fast winding number sign) and point-cloud-utils
  `signed_distance_to_mesh` on the first 100 000 points (they are slow);
- `topovox.sample` with DeepSDF's 500 000 near-surface points, loading included.
Also the sign disagreements of each peer with topovox on those 100 000
points, and the largest distance difference.
"""
import os
import statistics
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "2")

import numpy as np

import topovox


def timed(f):
    t = time.perf_counter()
    out = f()
    return time.perf_counter() - t, out


def main():
    path = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    m = topovox.load_mesh(path)
    v, f = np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)
    lo, hi = v.min(0), v.max(0)
    pad = (hi - lo) * 0.05
    pts = np.random.default_rng(0).uniform(lo - pad, hi + pad, size=(n, 3))
    sub = pts[:100_000]
    runs = {}
    build, q = timed(lambda: topovox.Query(m, threads=2))
    qp = topovox.Query(m, sign="parity", threads=2)
    print(f"{path}: {len(f)} triangles, {n} points; topovox Query built in {build:.3f} s ({q.facts})")
    import open3d as o3d

    def o3d_scene():
        s = o3d.t.geometry.RaycastingScene()
        s.add_triangles(o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(f.astype(np.uint32)))
        return s

    build, scene = timed(o3d_scene)
    print(f"Open3D scene built in {build:.3f} s")
    p32 = o3d.core.Tensor(pts.astype(np.float32))
    import igl
    import point_cloud_utils as pcu

    cases = {
        "topovox distance (signed)": lambda: q.distance(pts),
        "topovox contains (solid's rule)": lambda: q.contains(pts),
        "topovox contains (parity)": lambda: qp.contains(pts),
        "Open3D compute_signed_distance": lambda: scene.compute_signed_distance(p32).numpy(),
        "Open3D compute_occupancy": lambda: scene.compute_occupancy(p32).numpy(),
        "libigl signed_distance (fwn), 100k": lambda: igl.signed_distance(sub, v, f, sign_type=igl.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)[0],
        "pcu signed_distance_to_mesh, 100k": lambda: pcu.signed_distance_to_mesh(sub, v, f.astype(np.int32))[0],
        "topovox sample, DeepSDF 500k (with loading)": lambda: topovox.sample(path, near=500_000, sigma=(0.05, 0.0158), normalize="unit-sphere", threads=2),
    }
    for _ in range(reps):
        for name, fn in cases.items():
            t, out = timed(fn)
            runs.setdefault(name, []).append(t)
            runs.setdefault(name + " out", [out])
    ours = q.distance(sub)
    print(f"\n| what | median s | points/s |\n|---|---|---|")
    for name in cases:
        t = statistics.median(runs[name])
        count = 100_000 if "100k" in name else (500_000 if "sample" in name else n)
        print(f"| {name} | {t:.3f} | {count / t / 1e6:.2f} M |")
    o3d_sd = runs["Open3D compute_signed_distance out"][0][:100_000]
    igl_sd = runs["libigl signed_distance (fwn), 100k out"][0]
    pcu_sd = runs["pcu signed_distance_to_mesh, 100k out"][0]
    for name, other in (("Open3D", o3d_sd), ("libigl", igl_sd), ("pcu", pcu_sd)):
        signs = int(np.sum((other < 0) != (ours < 0)))
        diff = float(np.max(np.abs(np.abs(other) - np.abs(ours))))
        print(f"{name}: sign differs from topovox on {signs} of 100 000 points; largest |distance| difference {diff:.2e}")


if __name__ == "__main__":
    main()
