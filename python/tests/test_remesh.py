"""`topovox remesh` and `topovox check MESH` (issue 55): every guarantee of
the watertight mesh, tested on every output — by our certificate, by
PyMeshLab where it installs (an independent check of manifoldness and
self-intersections), and by winding numbers computed here in NumPy."""

import inspect
import json
import subprocess

import numpy as np
import pytest

import topovox
from topovox import _topovox

REMESH_OPTIONS = _topovox.options("remesh")


def winding(vertices, faces, points):
    """Winding numbers of the closed mesh at `points` (Van Oosterom and
    Strackee's solid angles), float64; exact enough away from the surface."""
    out = np.empty(len(points))
    tri = vertices[faces]
    chunk = max(1, 500_000 // len(faces))
    for s in range(0, len(points), chunk):
        p = points[s : s + chunk, None, None, :]
        a, b, c = (tri[None, :, k, :] - p[:, :, 0, :] for k in range(3))
        la, lb, lc = (np.linalg.norm(v, axis=-1) for v in (a, b, c))
        num = np.einsum("...i,...i", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("...i,...i", a, b) * lc + np.einsum("...i,...i", b, c) * la + np.einsum("...i,...i", c, a) * lb
        out[s : s + chunk] = (2 * np.arctan2(num, den)).sum(axis=1) / (4 * np.pi)
    return out


def centres(grid):
    """World centres of every voxel of a VoxelGrid, C order."""
    idx = np.indices(grid.shape).reshape(3, -1).T
    return grid.origin + (idx + 0.5) * np.asarray(grid.spacing)


def certify(mesh, info=None):
    """Our certificate, and PyMeshLab's where it installs."""
    c = topovox.check_mesh(mesh)
    assert c["watertight"], c
    if info is not None:
        assert info["certificate"] == c
    try:
        import pymeshlab
    except ImportError:
        return c
    # MeshLab's triangle test (Moller's) compares unnormalised products
    # with an absolute 1e-6: the mesh is scaled to a 100-unit box first so
    # that small models are judged by their shape, not their units.
    v = mesh.vertices - mesh.vertices.min(axis=0)
    v *= 100.0 / v.max()
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=mesh.faces.astype(np.int32)))
    topo = ms.get_topological_measures()
    assert topo["non_two_manifold_edges"] == 0 and topo["non_two_manifold_vertices"] == 0, topo
    assert topo["boundary_edges"] == 0, topo
    assert topo["connected_components_number"] == c["components"], topo
    ms.compute_selection_by_self_intersections_per_face()
    flagged = np.nonzero(ms.current_mesh().face_selection_array())[0]
    explained = {f for p in pairs_among(v, mesh.faces, flagged) if coplanar_apart(v[mesh.faces[p[0]]], v[mesh.faces[p[1]]]) for f in p}
    assert set(flagged.tolist()) == explained, sorted(set(flagged.tolist()) - explained)
    return c


def pairs_among(v, faces, flagged):
    """The pairs of flagged faces whose boxes overlap."""
    tri = v[faces[flagged]]
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    overlap = ((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :])).all(axis=2)
    i, j = np.nonzero(np.triu(overlap, 1))
    return list(zip(flagged[i], flagged[j]))


def coplanar_apart(a, b):
    """MeshLab flags every pair of exactly coplanar faces whose boxes
    overlap (its coplanar branch does not test further): such a pair is a
    false positive when the two triangles, in their plane, lie apart by a
    gap (no edge crossing, no vertex inside the other, a positive
    distance). Pairs that are not coplanar are MeshLab's verdict."""
    n = np.cross(a[1] - a[0], a[2] - a[0])
    if np.abs((b - a[0]) @ n).max() > 1e-9 * np.linalg.norm(n) * np.abs(a).max():
        return False
    keep = [k for k in range(3) if k != int(np.argmax(np.abs(n)))]
    a2, b2 = a[:, keep], b[:, keep]

    def side(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    def seg_dist(p, q, r):
        d = q - p
        t = np.clip((r - p) @ d / (d @ d), 0, 1)
        return np.linalg.norm(p + t * d - r)

    def inside(t, p):
        s = [side(t[k], t[(k + 1) % 3], p) for k in range(3)]
        return min(s) >= 0 or max(s) <= 0

    for x, y in ((a2, b2), (b2, a2)):
        if any(inside(y, p) for p in x):
            return False
        for k in range(3):
            p, q = x[k], x[(k + 1) % 3]
            for m in range(3):
                r, s = y[m], y[(m + 1) % 3]
                if side(p, q, r) * side(p, q, s) < 0 and side(r, s, p) * side(r, s, q) < 0:
                    return False
    gap = min(seg_dist(x[k], x[(k + 1) % 3], p) for x, y in ((a2, b2), (b2, a2)) for k in range(3) for p in y)
    return gap > 1e-6 * np.abs(a2).max()


def test_the_remesh_signature_is_its_table():
    params = set(inspect.signature(topovox.remesh).parameters) - {"mesh_or_vertices", "faces", "info"}
    assert params == {name for name, _, _ in REMESH_OPTIONS}
    assert set(_topovox.choices()["inside"]) == {"auto", "parity", "winding", "wrap"}


@pytest.mark.parametrize("name", ["stanford-bunny.obj", "cow.obj", "teapot.obj", "fandisk.obj", "beetle.obj"])
@pytest.mark.parametrize("inside", ["auto", "wrap"])
@pytest.mark.parametrize("surface", ["smooth", "blocky"])
def test_every_guarantee_on_the_shared_meshes(meshes, name, inside, surface):
    src = topovox.load_mesh(meshes / name)
    info = {}
    # Blocky surfaces have about four times the faces: a coarser grid.
    res = 20 if surface == "smooth" else 12
    out = topovox.remesh(src, resolution=res, inside=inside, surface=surface, check=True, info=info)
    c = certify(out, info)
    assert c["volume"] > 0 and c["components"] >= info["parts"] >= 1
    # (5) separation: winding 1 at the inside centres, 0 at every other.
    if inside != "wrap":
        solid = topovox.voxelize(src, resolution=res, mode="solid", method=inside)
        w = winding(out.vertices, out.faces, centres(solid))
        assert np.array_equal(np.round(w).astype(int), solid.occupancy.reshape(-1).astype(int))
        assert np.abs(w - np.round(w)).max() < 1e-6
        assert info["inside_voxels"] == solid.count
    else:
        # (7) wrap contains the input: its vertices (a sample) are inside;
        # the shell lies 1.5 to a few voxels off the input.
        used = src.vertices[np.unique(src.faces)]
        w = winding(out.vertices, out.faces, used[np.random.default_rng(0).permutation(len(used))[:1500]])
        assert (np.round(w) == 1).all() and info["distance_voxels"]["input_to_output_max"] < 5


def test_random_rotations_and_soups(meshes):
    rng = np.random.default_rng(4)
    src = topovox.load_mesh(meshes / "cow.obj")
    for _ in range(3):
        q, _r = np.linalg.qr(rng.normal(size=(3, 3)))
        rotated = topovox.Mesh(src.vertices @ q.T, src.faces)
        for surface in ("smooth", "blocky"):
            certify(topovox.remesh(rotated, resolution=24, surface=surface))
    for n in (5, 40):
        v = rng.uniform(-1, 1, size=(3 * n, 3))
        soup = topovox.Mesh(v, np.arange(3 * n).reshape(n, 3))
        for inside in ("winding", "wrap"):
            try:
                out = topovox.remesh(soup, resolution=16, inside=inside, surface="smooth")
            except ValueError as e:
                assert inside != "wrap" and ("nothing to close" in str(e) or "encloses no volume" in str(e))
                continue
            certify(out)


def test_every_part_is_kept_and_min_part_drops_only_when_asked():
    cube = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    faces = np.array([t for q in quads for t in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])])
    small = cube * 0.15 + [3, 0, 0]
    v = np.vstack([cube, small])
    f = np.vstack([faces, faces + 8])
    info = {}
    out = topovox.remesh(v, f, voxel_size=0.1, info=info)
    assert (info["parts"], certify(out)["components"]) == (2, 2)
    info = {}
    out = topovox.remesh(v, f, voxel_size=0.1, min_part=10, info=info)
    assert (info["parts"], info["dropped_parts"], topovox.check_mesh(out)["components"]) == (1, 1, 1)


@pytest.mark.parametrize("name", ["stanford-bunny.obj", "fandisk.obj", "beetle.obj"])
@pytest.mark.parametrize("inside", ["auto", "wrap"])
@pytest.mark.parametrize("surface", ["smooth", "blocky"])
def test_simplify_keeps_every_guarantee(meshes, name, inside, surface):
    """--simplify: far fewer faces, still certified (ours and PyMeshLab),
    still separating the same voxel centres (NumPy winding numbers)."""
    src = topovox.load_mesh(meshes / name)
    res = 20 if surface == "smooth" else 12
    full, fewer = {}, {}
    a = topovox.remesh(src, resolution=res, inside=inside, surface=surface, info=full)
    b = topovox.remesh(src, resolution=res, inside=inside, surface=surface, simplify=1.0, check=True, info=fewer)
    s = fewer["simplify"]
    assert s["kept"] and s["faces_before"] == len(a.faces) and s["faces"] == len(b.faces), s
    assert len(b.faces) * 3 < len(a.faces), (len(b.faces), len(a.faces))
    assert set(map(tuple, b.vertices)) <= set(map(tuple, a.vertices))  # every vertex is one of the surface's own
    certify(b, fewer)
    # (5) the same centres inside: the solid's (wrap pads the grid by one).
    grid = topovox.voxelize(src, resolution=res, mode="solid", method="auto", pad=1 if inside == "wrap" else 0)
    points = centres(grid)
    w = winding(b.vertices, b.faces, points)
    assert np.abs(w - np.round(w)).max() < 1e-6
    if inside == "wrap":
        assert np.array_equal(np.round(w), np.round(winding(a.vertices, a.faces, points)))
    else:
        assert np.array_equal(np.round(w).astype(int), grid.occupancy.reshape(-1).astype(int))


def test_simplify_is_refused_out_of_range(meshes):
    src = topovox.load_mesh(meshes / "cow.obj")
    for bad in (-0.5, 3, float("nan")):
        with pytest.raises(ValueError, match="simplify"):
            topovox.remesh(src, resolution=16, simplify=bad)


@pytest.mark.parametrize(
    "extra", [[], ["--surface", "blocky"], ["--inside", "wrap"], ["--inside", "parity", "--surface", "blocky"], ["--simplify", "1"]]
)
def test_threads_give_the_same_bytes(meshes, cli, tmp_path, extra):
    outs = []
    for t in (1, 2):
        out = tmp_path / f"b{t}.ply"
        subprocess.run([cli, "remesh", meshes / "stanford-bunny.obj", "-o", out, "--resolution", "48", "--threads", str(t), "--quiet", *extra], check=True)
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]


@pytest.mark.parametrize("fmt", ["obj", "ply", "stl", "glb"])
def test_the_cli_writes_certified_files_in_every_format(meshes, cli, tmp_path, fmt):
    out = tmp_path / f"bunny.{fmt}"
    r = subprocess.run(
        [cli, "remesh", meshes / "stanford-bunny.obj", "-o", out, "--resolution", "32", "--check", "--json"], check=True, capture_output=True, text=True
    )
    summary = json.loads(r.stdout)
    assert summary["certificate"]["watertight"] and summary["triangles"] > 0
    r = subprocess.run([cli, "check", out, "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    back = json.loads(r.stdout)
    assert back["watertight"] and back["faces"] == summary["triangles"]


@pytest.mark.parametrize("fmt,resolution", [("obj", 40), ("ply", 40), ("stl", 40), ("glb", 40), ("ply", 560)])
def test_a_streamed_file_is_the_mesh_made_whole(meshes, cli, tmp_path, fmt, resolution):
    """Without --check the CLI makes and writes a surface past what one slab
    may hold slab by slab, never whole (at 560 under --max-memory 400M the
    bunny's surface is six slabs): the same file as the --check run,
    which holds the mesh, and the mesh topovox.remesh returns."""
    src = meshes / "stanford-bunny.obj"
    streamed, whole = tmp_path / f"s.{fmt}", tmp_path / f"w.{fmt}"
    bound = ["--max-memory", "400M"] if resolution > 40 else []
    for out, extra in [(streamed, bound), (whole, ["--check"])]:
        subprocess.run([cli, "remesh", src, "-o", out, "--resolution", str(resolution), "--quiet", *extra], check=True)
    if fmt == "obj":
        # Each slab's vertices come before its faces: the same mesh, in
        # another order of lines.
        a, b = topovox.load_mesh(streamed), topovox.load_mesh(whole)
        assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    else:
        assert streamed.read_bytes() == whole.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([streamed.name, whole.name]), "no scratch file is left"
    if fmt != "stl" and resolution <= 40:
        # (STL has no shared vertices to compare; its bytes are the --check run's.)
        one = topovox.remesh(topovox.load_mesh(src), resolution=resolution)
        back = topovox.load_mesh(streamed)
        want = one.vertices.astype(np.float32) if fmt == "glb" else one.vertices
        assert np.array_equal(back.vertices, want) and np.array_equal(back.faces, one.faces)


def test_check_exits_non_zero_on_a_requested_failure(meshes, cli):
    r = subprocess.run([cli, "check", meshes / "stanford-bunny.obj"], capture_output=True, text=True)
    assert r.returncode == 1 and "not watertight" in r.stderr and "closed: NO (223 boundary edges" in r.stdout
    r = subprocess.run([cli, "check", meshes / "stanford-bunny.obj", "--require", "manifold,oriented"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    c = topovox.check_mesh(meshes / "stanford-bunny.obj")
    assert (c["boundary_edges"], c["manifold"], c["self_intersections"]) == (223, True, 0)


@pytest.mark.parametrize(
    "vertices,faces,message",
    [
        (np.zeros((0, 3)), np.zeros((0, 3), int), "no triangles"),
        ([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]], "nothing to close"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(vertices, faces, message, cli, tmp_path):
    with pytest.raises(ValueError, match=message):
        topovox.remesh(vertices, faces, resolution=8, inside="wrap")
    src = tmp_path / "bad.obj"
    topovox.Mesh(np.asarray(vertices, float).reshape(-1, 3), np.asarray(faces).reshape(-1, 3)).save(src) if len(faces) else src.write_text("")
    r = subprocess.run([cli, "remesh", src, "-o", tmp_path / "out.obj"], capture_output=True, text=True)
    assert r.returncode != 0 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "out.obj").exists()


def test_a_grid_past_memory_is_refused_before_any_work(meshes, cli, tmp_path):
    out = tmp_path / "big.ply"
    r = subprocess.run([cli, "remesh", meshes / "stanford-bunny.obj", "-o", out, "--resolution", "2048", "--max-memory", "64M"], capture_output=True, text=True)
    assert r.returncode != 0 and "more than the" in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not out.exists()
    with pytest.raises(RuntimeError, match="raise --max-memory"):
        topovox.remesh(meshes / "stanford-bunny.obj", resolution=2048, max_memory="64M")


def test_batch_and_dask_remesh_folders_as_the_cli_does(meshes, cli, tmp_path):
    """The batch (Python and CLI) and the Dask helper run remesh over a
    folder, resumable, writing what `topovox.remesh` makes; `surface` is
    remesh's under run="remesh"."""
    from conftest import run_cli

    root = tmp_path / "in"
    (root / "sub").mkdir(parents=True)
    for name, where in [("cow.obj", root), ("teapot.obj", root / "sub")]:
        (where / name).write_bytes((meshes / name).read_bytes())
    py_out, cli_out = tmp_path / "py", tmp_path / "cli"
    s = topovox.batch(root, py_out, run="remesh", surface="blocky", resolution=20, format="ply")
    assert (s["done"], s["failed"]) == (2, 0), s
    run_cli(cli, "batch", root, "-o", cli_out, "--run", "remesh", "--surface", "blocky", "--resolution", 20, "--format", "ply", "--quiet")
    for rel in ["cow.ply", "sub/teapot.ply"]:
        assert (py_out / rel).read_bytes() == (cli_out / rel).read_bytes(), rel
    one = topovox.remesh(topovox.load_mesh(root / "cow.obj"), surface="blocky", resolution=20)
    back = topovox.load_mesh(py_out / "cow.ply")
    assert np.array_equal(back.vertices, one.vertices) and np.array_equal(back.faces, one.faces)
    certify(back)
    # The CLI resumes the Python run; other options are refused by name.
    assert topovox.batch(root, py_out, run="remesh", surface="blocky", resolution=20, format="ply")["skipped"] == 2
    with pytest.raises(FileExistsError, match="surface"):
        topovox.batch(root, py_out, run="remesh", resolution=20, format="ply")
    with pytest.raises(ValueError, match="unknown option"):
        topovox.batch(root, tmp_path / "x", run="remesh", mode="solid")
    with pytest.raises(ValueError, match="remesh"):
        topovox.batch(root, tmp_path / "y", run="remesh", format="npy")
    # Dask: one task per mesh, the same files, obj by default.
    pytest.importorskip("dask")
    import topovox.dask as vd

    ref = tmp_path / "ref"
    topovox.batch(root, ref, run="remesh", resolution=16)
    records = vd.voxelize_paths([root], tmp_path / "dask", run="remesh", resolution=16).compute(scheduler="threads")
    assert sorted(r["status"] for r in records) == ["done", "done"]
    for rel in ["cow.obj", "sub/teapot.obj"]:
        assert (tmp_path / "dask" / rel).read_bytes() == (ref / rel).read_bytes(), rel
