"""`topovox spray`'s point cloud read by a standard PLY reader (plyfile): as
many points as the summary says, every point on the mesh's surface (closest
points by trimesh, within a stated epsilon), unit normals facing the camera,
finite light terms, some points lit and some in shadow.

Usage: check_spray.py TOPOVOX OUTDIR
"""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import trimesh
from plyfile import PlyData

from oracle import Oracle

topovox, out = sys.argv[1], Path(sys.argv[2])
o = Oracle(topovox)
obj, cloud = out / "spray-cornell.obj", out / "spray.ply"
subprocess.run([topovox, "scene", "cornell", "-o", str(obj)], check=True, capture_output=True)
eye, target = np.array([0.5, 0.6, 2.3]), np.array([0.45, 0.4, 0.0])
cam = ",".join(str(v) for v in [*eye, *target, 50])
r = subprocess.run([topovox, "spray", str(obj), "-o", str(cloud), "--rays", "20000", "--camera", cam, "--size", "400x400", "--json"],
                   capture_output=True, text=True)
if r.returncode != 0:
    raise SystemExit(f"topovox spray failed: {r.stderr}")
summary = json.loads(r.stdout)
v = PlyData.read(str(cloud))["vertex"]
o.check("plyfile reads as many points as the summary says", v.count == summary["points"] > 10000, (v.count, summary["points"]))
p = np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64)
n = np.stack([v["nx"], v["ny"], v["nz"]], 1).astype(np.float64)

mesh = trimesh.load(str(obj), force="mesh")
tris = mesh.triangles
# Distance from every point to every triangle (36 triangles): the minimum.
best = np.full(len(p), np.inf)
for t in tris:
    q = trimesh.triangles.closest_point(np.repeat(t[None], len(p), 0), p)
    best = np.minimum(best, np.linalg.norm(q - p, axis=1))
# f32 hit points of a unit box: 1e-5 of the box is a few ulps.
eps = 1e-5
o.check(f"every point lies on the mesh (distance <= {eps})", best.max() <= eps, best.max())
o.check("normals have unit length", np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5))
o.check("normals face the camera", bool((np.einsum("ij,ij->i", n, eye - p) >= 0).all()))
light = np.stack([v["light_r"], v["light_g"], v["light_b"]], 1)
o.check("light terms finite and non-negative", bool(np.isfinite(light).all() and (light >= 0).all()))
o.check("some points lit, some in shadow or facing away", bool((light[:, 0] > 0).any() and (light[:, 0] == 0).any()))
o.check("red wall points keep their albedo", bool(np.isclose(v["albedo_r"][p[:, 0] < 1e-6], 0.65, atol=1e-6).all()))
o.finish()
