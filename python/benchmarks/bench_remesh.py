"""Watertight meshes against point-cloud-utils and OpenVDB, side by side
(issue 55), with each output's certificate.

    python3 python/benchmarks/bench_remesh.py drive TOPOVOX MESHES [REPEATS]

Runs, in alternation and `REPEATS` times each (default 3), reporting medians:
- `topovox remesh MESH -o x.ply --resolution R --threads 2` (the whole
  command: loading, inside, surface, writing; wall time of the process);
- OpenVDB's level set and `volumeToMesh` (`createLevelSetFromPolygons`,
  half width 3, then `convertToPolygons`) on the same voxel size, in
  Debian's Python (`/usr/bin/python3`, python3-openvdb): reading the OBJ,
  both steps and writing an OBJ, timed inside its process;
- point-cloud-utils' `make_mesh_watertight` (the ManifoldPlus family) at
  20 000 leaves, in this Python (`pip install point-cloud-utils`): reading,
  the call and writing, timed inside its process;
on the Stanford bunny (open, 69 451 triangles), the fandisk (closed) and
the bunny subdivided once (277 804 triangles), at 128, 256 and 512. Then
`topovox check` certifies every output: closed, manifold, self-intersecting
pairs, components, and the volume against ours (a lost body shows).
`openvdb` and `pcu` are this script's other modes.
"""
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_sdf import load_obj, subdivide  # noqa: E402


def write_obj(path, v, f):
    with open(path, "w") as out:
        out.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in v.tolist())
        out.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f.tolist())


def openvdb_mode(mesh, res, out):
    import pyopenvdb as vdb

    start = time.perf_counter()
    v, f = load_obj(mesh)
    h = (v.max(axis=0) - v.min(axis=0)).max() / int(res)
    xf = vdb.createLinearTransform(voxelSize=h)
    g = vdb.FloatGrid.createLevelSetFromPolygons(v.astype(np.float32), triangles=f.astype(np.int32), transform=xf, halfWidth=3.0)
    points, tris, quads = g.convertToPolygons(isovalue=0.0)
    faces = np.vstack([tris.reshape(-1, 3), quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]) if len(quads) else tris
    write_obj(out, points.astype(np.float64), faces.astype(np.int64))
    print(time.perf_counter() - start)


def pcu_mode(mesh, leaves, out):
    import point_cloud_utils as pcu

    start = time.perf_counter()
    v, f = load_obj(mesh)
    vw, fw = pcu.make_mesh_watertight(v, f, resolution=int(leaves))
    write_obj(out, vw, fw)
    print(time.perf_counter() - start)


def check(topovox, path):
    r = subprocess.run([topovox, "check", path, "--json"], capture_output=True, text=True)
    return json.loads(r.stdout) if r.stdout else {"error": r.stderr.strip()}


def drive(topovox, meshes, repeats):
    tmp = Path(tempfile.mkdtemp())
    sub = tmp / "bunny-subdivided.obj"
    subdivide(Path(meshes) / "stanford-bunny.obj", sub)
    cases = [("bunny (open, 69k)", Path(meshes) / "stanford-bunny.obj"), ("fandisk (closed, 13k)", Path(meshes) / "fandisk.obj"), ("bunny x4 (278k)", sub)]
    rows, certs = [], []
    for label, mesh in cases:
        for res in (128, 256, 512):
            times = {"topovox": [], "openvdb": []}
            outs = {"topovox": tmp / "ours.ply", "openvdb": tmp / "vdb.obj"}
            for _ in range(repeats):
                start = time.perf_counter()
                subprocess.run([topovox, "remesh", mesh, "-o", outs["topovox"], "--resolution", str(res), "--threads", "2", "--quiet"], check=True)
                times["topovox"].append(time.perf_counter() - start)
                r = subprocess.run(["/usr/bin/python3", __file__, "openvdb", mesh, str(res), outs["openvdb"]], capture_output=True, text=True, check=True)
                times["openvdb"].append(float(r.stdout.split()[-1]))
            med = {k: statistics.median(v) for k, v in times.items()}
            rows.append(f"| {label} | {res} | {med['topovox']:.2f} | {med['openvdb']:.2f} | {med['openvdb'] / med['topovox']:.1f}x |")
            if res == 256:
                ours = check(topovox, outs["topovox"])
                for tool in ("topovox", "openvdb"):
                    certs.append(cert_row(label, f"{tool} 256", check(topovox, outs[tool]), ours))
        pcu_out = tmp / "pcu.obj"
        pt = []
        for _ in range(repeats):
            r = subprocess.run([sys.executable, __file__, "pcu", mesh, "20000", pcu_out], capture_output=True, text=True, check=True)
            pt.append(float(r.stdout.split()[-1]))
        rows.append(f"| {label} | pcu 20k leaves | | | pcu {statistics.median(pt):.2f} s |")
        certs.append(cert_row(label, "pcu 20k", check(topovox, pcu_out), ours))
    print("| mesh | resolution | topovox remesh s | OpenVDB level set + volumeToMesh s | OpenVDB / topovox |")
    print("|---|---|---|---|---|")
    print("\n".join(rows))
    print()
    print("| mesh | tool | faces | closed | manifold | self-intersecting pairs | components | volume / ours |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(certs))


def cert_row(label, tool, c, ours):
    if "error" in c:
        return f"| {label} | {tool} | {c['error'][:60]} | | | | | |"
    yes = lambda b: "yes" if b else "NO"  # noqa: E731
    ratio = c["volume"] / ours["volume"] if ours.get("volume") else float("nan")
    return f"| {label} | {tool} | {c['faces']} | {yes(c['closed'])} | {yes(c['manifold'])} | {c['self_intersections']} | {c['components']} | {ratio:.3f} |"


if __name__ == "__main__":
    mode = sys.argv[1]
    if mode == "openvdb":
        openvdb_mode(*sys.argv[2:5])
    elif mode == "pcu":
        pcu_mode(*sys.argv[2:5])
    else:
        drive(sys.argv[2], sys.argv[3], int(sys.argv[4]) if len(sys.argv) > 4 else 3)
