"""Solids on real-world meshes (issue 66), through the Python API and the
CLI: flipped faces, overlapping and nested shells, sheets. The solid of a
repaired mesh equals the clean mesh's; remeshes of them are certified
(our exact certificate, and trueform's exact self-intersection test where
it installs); sheets are refused in one line naming ``--inside wrap``, and
wrap gives one shell within 3 voxels of the sheet."""

import json
import subprocess

import numpy as np
import pytest

import topovox


def flipped(mesh, fraction, seed):
    rng = np.random.default_rng(seed)
    f = mesh.faces.copy()
    pick = rng.random(len(f)) < fraction
    f[pick] = f[pick][:, ::-1]
    return topovox.Mesh(mesh.vertices, f)


def icosphere(center, radius, subdivisions=3):
    t = (1 + 5**0.5) / 2
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
         [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    v = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid = {}
        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[key] = len(v) - 1
            return mid[key]
        f = [t for a, b, c in f for t in ([a, m(a, b), m(c, a)], [b, m(b, c), m(a, b)], [c, m(c, a), m(b, c)], [m(a, b), m(b, c), m(c, a)])]
    return topovox.Mesh(np.array(v) * radius + center, np.array(f))


def joined(*meshes):
    vs, fs, base = [], [], 0
    for m in meshes:
        vs.append(m.vertices)
        fs.append(m.faces + base)
        base += len(m.vertices)
    return topovox.Mesh(np.vstack(vs), np.vstack(fs))


def wavy_sheet(n=40):
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    v = np.c_[x.ravel(), y.ravel(), (0.08 * np.sin(6 * x) * np.cos(5 * y)).ravel()]
    f = []
    for r in range(n - 1):
        for c in range(n - 1):
            a = r * n + c
            f += [[a, a + 1, a + n], [a + 1, a + n + 1, a + n]]
    return topovox.Mesh(v, np.array(f))


def no_self_intersection(mesh):
    """trueform's exact self-intersection test, where it installs."""
    try:
        import trueform as tf
    except ImportError:
        return
    m = tf.Mesh(np.ascontiguousarray(mesh.faces, dtype=np.int32), np.ascontiguousarray(mesh.vertices, dtype=np.float64))
    assert not tf.has_self_intersections(m)


def test_flipped_faces_give_the_clean_solid(meshes):
    spot = topovox.load_mesh(meshes / "spot-textured.obj")
    clean = topovox.voxelize(spot, resolution=48, mode="solid")
    for fraction, seed in [(0.1, 1), (0.3, 2), (0.5, 3)]:
        m = flipped(spot, fraction, seed)
        g = topovox.voxelize(m, resolution=48, mode="solid", threads=1 + seed % 2)
        assert np.array_equal(g.occupancy, clean.occupancy), fraction
        q = topovox.Query(m)
        assert q.facts["orientation"]["faces_reoriented"] > 0
        info = {}
        out = topovox.remesh(m, resolution=32, check=True, info=info)
        assert info["certificate"]["watertight"] and info["parts"] == 1
        no_self_intersection(out)
    # voxelize_many's solids too: the flipped item equals the clean one.
    batch = topovox.voxelize_many([spot, flipped(spot, 0.3, 9)], mode="solid", resolution=32)
    n = batch.offsets
    assert n[1] - n[0] == n[2] - n[1] > 0
    coords = np.asarray(batch.coords)
    assert np.array_equal(coords[n[0] : n[1], 1:], coords[n[1] : n[2], 1:])


def test_overlapping_shells_give_their_union_and_nested_ones_cavities():
    a, b = icosphere([0, 0, 0], 1.0), icosphere([0.8, 0.3, 0.1], 0.9)
    both = flipped(joined(a, b), 0.3, 5)
    grid = topovox.voxelize(both, resolution=40, mode="solid")
    opts = dict(origin=grid.origin, voxel_size=grid.spacing, dims=grid.shape, mode="solid", method="parity")
    union = topovox.voxelize(a, **opts).occupancy | topovox.voxelize(b, **opts).occupancy
    assert np.array_equal(grid.occupancy, union)
    assert topovox.voxelize(both, **opts).count < grid.count  # parity cuts the overlap out
    info = {}
    out = topovox.remesh(both, resolution=32, check=True, info=info)
    assert info["parts"] == 1 and topovox.check_mesh(out)["components"] == 1
    no_self_intersection(out)
    # A ball inside a ball, faced the same way: a cavity.
    nested = joined(icosphere([0, 0, 0], 1.0), icosphere([0, 0, 0], 0.5))
    g = topovox.voxelize(nested, resolution=32, mode="solid")
    assert not g.occupancy[16, 16, 16] and g.occupancy[16, 16, 4]
    info = {}
    topovox.remesh(nested, resolution=32, check=True, info=info)
    assert info["solid"]["orientation"]["nested_parts"] == 1


def test_sheets_are_refused_and_wrapped(tmp_path, cli):
    sheet = wavy_sheet()
    path = tmp_path / "sheet.obj"
    path.write_text("".join(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in sheet.vertices) + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in sheet.faces))
    for args in (["voxelize", str(path), "-o", str(tmp_path / "s.npy"), "--mode", "solid"],
                 ["sdf", str(path), "-o", str(tmp_path / "s.vdb")],
                 ["remesh", str(path), "-o", str(tmp_path / "s.obj")]):
        r = subprocess.run([str(cli), *args], capture_output=True, text=True)
        assert r.returncode != 0 and len(r.stderr.strip().splitlines()) == 1, (args, r.stderr)
        assert "encloses no volume" in r.stderr and "--inside wrap" in r.stderr, r.stderr
    with pytest.raises(ValueError, match="inside wrap"):
        topovox.voxelize(sheet, mode="solid", resolution=32)
    # Samples keep their exact distances and say the signs are a guess.
    r = subprocess.run([str(cli), "sample", str(path), "-o", str(tmp_path / "s.npz"), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert any("encloses no volume" in w for w in info["warnings"]) and info["orientation"]["sheets"] == 1, info
    for res in (64, 128):
        r = subprocess.run([str(cli), "remesh", str(path), "-o", str(tmp_path / "w.obj"), "--inside", "wrap", "--resolution", str(res), "--check", "--json"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        info = json.loads(r.stdout)
        assert info["parts"] == 1 and info["certificate"]["watertight"] and info["certificate"]["components"] == 1, info
        d = info["distance_voxels"]
        assert d["input_to_output_max"] < 3 and d["output_to_input_max"] < 3, d
