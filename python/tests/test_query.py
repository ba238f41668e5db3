"""Point queries and training samples (issue 56): exact against analytic
distances and brute force, equal to the grids at voxel centres, and
reproducible for a seed on any thread count."""

import subprocess

import numpy as np
import pytest

import topovox


def box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]] for i in range(8)])
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    f = np.array([t for q in quads for t in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])])
    return v, f


def rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def box_sdf(p, lo, hi):
    c, h = (np.asarray(lo) + hi) / 2, (np.asarray(hi) - lo) / 2
    d = np.abs(p - c) - h
    return np.linalg.norm(np.maximum(d, 0), axis=1) + np.minimum(d.max(axis=1), 0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_distances_equal_the_analytic_box_sdf(seed):
    lo, hi = np.array([-1.0, -0.5, -0.25]), np.array([1.0, 0.75, 0.5])
    v, f = box(lo, hi)
    r = rotation(seed)
    q = topovox.Query(v @ r.T, f)
    p = np.random.default_rng(seed).uniform(-2, 2, size=(20_000, 3))
    want = box_sdf(p, lo, hi)
    got = q.distance(p @ r.T)
    assert np.all(np.abs(got - want) <= 1e-9 * np.maximum(np.abs(want), 1e-9) + 1e-12)
    assert np.array_equal(q.contains(p @ r.T), want < 0)
    pts, d, tri, bary = q.closest(p @ r.T)
    assert np.allclose(np.linalg.norm(pts - p @ r.T, axis=1), np.abs(want), atol=1e-9)
    corners = (v @ r.T)[f[tri]]
    assert np.allclose(np.einsum("nk,nkj->nj", bary, corners), pts, atol=1e-9)
    # A closed mesh: auto is the nonzero winding number of the oriented mesh.
    assert q.facts["watertight"] and q.facts["sign"] == "winding"
    assert q.facts["orientation"]["closed_parts"] == 1 and q.facts["orientation"]["faces_reoriented"] == 0


def dyadic(mesh, res):
    """The mesh's vertices on the 1/4096 lattice of a power-of-two grid,
    and that grid's origin, voxel size and dims."""
    v = np.asarray(mesh.vertices, dtype=np.float64)
    lo, hi = v.min(0), v.max(0)
    h = 2.0 ** np.floor(np.log2((hi - lo).max() / res))
    origin = np.floor(lo / h) * h - h
    dims = (np.ceil((hi - origin) / h) + 1).astype(int)
    step = h / 4096
    return origin + np.round((v - origin) / step) * step, np.asarray(mesh.faces), origin, h, dims


@pytest.mark.parametrize("name", ["stanford-bunny.obj", "teapot.obj", "suzanne.obj"])
def test_contains_and_signed_distance_equal_the_grids(name, meshes):
    v, f, origin, h, dims = dyadic(topovox.load_mesh(meshes / name), 24)
    grid = topovox.voxelize(v, f, mode="solid", origin=origin, voxel_size=h, dims=dims)
    field = topovox.sdf(v, f, origin=origin, voxel_size=h, dims=dims, band="all")
    idx = np.indices(grid.shape).reshape(3, -1).T
    centres = grid.index_to_world(idx)
    q = topovox.Query(v, f)
    assert np.array_equal(q.contains(centres).reshape(grid.shape), np.asarray(grid))
    d = q.distance(centres).astype(np.float32).reshape(grid.shape)
    assert np.array_equal(d.view(np.uint32), np.asarray(field).view(np.uint32))


@pytest.mark.parametrize("name", ["stanford-bunny.obj", "teapot.obj", "fandisk.obj", "beetle.obj"])
@pytest.mark.parametrize("seed", [None, 5])
def test_on_any_mesh_contains_and_the_sign_equal_the_grids(name, seed, meshes):
    """The solids are decided on the vertices as given (the lattice's result
    checked again where snapping could change it): equal at every centre,
    rotated, on grids of boxes, for the sparse path too."""
    m = topovox.load_mesh(meshes / name)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    if seed is not None:
        v = v @ rotation(seed).T
    q = topovox.Query(v, f)
    for kw in (dict(resolution=96), dict(voxel_size=tuple((v.max(0) - v.min(0)) / [40, 57, 33]))):
        grid = topovox.voxelize(v, f, mode="solid", **kw)
        centres = grid.index_to_world(np.indices(grid.shape).reshape(3, -1).T)
        assert np.array_equal(q.contains(centres), np.asarray(grid).reshape(-1)), kw
    field = topovox.sdf(v, f, resolution=64, band="all")
    centres = field.index_to_world(np.indices(field.shape).reshape(3, -1).T)
    d = q.distance(centres).astype(np.float32)
    assert np.array_equal(d.view(np.uint32), np.asarray(field).reshape(-1).view(np.uint32))


def test_winding_numbers_match_the_direct_sum(meshes):
    m = topovox.load_mesh(meshes / "teapot.obj")
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    p = np.random.default_rng(3).uniform(v.min(0), v.max(0), size=(300, 3))
    a, b, c = (v[f[:, i]][None] - p[:, None] for i in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
    det = np.einsum("pti,pti->pt", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("pti,pti->pt", a, b) * lc + np.einsum("pti,pti->pt", b, c) * la + np.einsum("pti,pti->pt", c, a) * lb
    direct = (2 * np.arctan2(det, den)).sum(1) / (4 * np.pi)
    q = topovox.Query(m)
    assert np.allclose(q.winding_number(p), direct, atol=1e-9)
    assert q.facts["sign"] == "winding"
    assert np.array_equal(q.contains(p), np.abs(q.winding_number(p)) >= 0.5)


def test_points_in_any_layout_and_bad_points():
    v, f = box([0, 0, 0], [1, 1, 1])
    q = topovox.Query(v, f, threads=1)
    p = np.random.default_rng(0).uniform(-1, 2, size=(1000, 6))[:, ::2]
    assert np.array_equal(q.distance(p), q.distance(np.ascontiguousarray(p)))
    assert np.allclose(q.distance(p.astype(np.float32)), q.distance(p.astype(np.float32).astype(np.float64)))
    assert q.distance([0.5, 0.5, 2.0]) == 1.0 and q.contains([0.5, 0.5, 0.5])
    bad = np.array([[np.nan, 0, 0], [0, np.inf, 0]])
    assert np.isnan(q.distance(bad)).all() and not q.contains(bad).any()
    assert list(q.closest(bad)[2]) == [-1, -1]
    assert topovox.distance(v, [[0.5, 0.5, 2.0]], faces=f)[0] == 1.0
    assert topovox.contains(v, [[0.5, 0.5, 0.5]], faces=f)[0]
    with pytest.raises(ValueError, match="shape"):
        q.distance(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="no triangles"):
        topovox.Query(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    with pytest.raises(ValueError, match="sign"):
        topovox.Query(v, f, sign="odd")


def test_samples_are_reproducible_and_consistent(meshes):
    # The values as computed (float64): the distances are checked against the query's.
    kw = dict(surface=3000, near=6000, sigma=(0.01, 0.05), uniform=5000, normalize="unit-cube", seed=4, dtype=np.float64)
    one = topovox.sample(meshes / "stanford-bunny.obj", threads=1, **kw)
    two = topovox.sample(meshes / "stanford-bunny.obj", threads=2, **kw)
    for k in ("points", "sdf", "occupancy", "normals", "kind"):
        assert np.array_equal(one[k], two[k], equal_nan=k == "normals"), k
    assert len(one["points"]) == 14_000 and np.array_equal(np.bincount(one["kind"]), [3000, 6000, 5000])
    assert np.array_equal(one["sdf"] < 0, one["occupancy"])
    surf = one["kind"] == 0
    assert np.allclose(np.linalg.norm(one["normals"][surf], axis=1), 1) and np.isnan(one["normals"][~surf]).all()
    assert np.abs(one["sdf"][surf]).max() < 1e-12
    p = one["points"] / one["scale"] + one["offset"]
    q = topovox.Query(meshes / "stanford-bunny.obj")
    assert np.allclose(np.abs(q.distance(p)), np.abs(one["sdf"]) / one["scale"], atol=1e-9)
    uni = one["points"][one["kind"] == 2]
    assert np.all(uni >= one["bounds"][0]) and np.all(uni <= one["bounds"][1])
    assert not np.array_equal(topovox.sample(meshes / "stanford-bunny.obj", surface=10, seed=5)["points"], topovox.sample(meshes / "stanford-bunny.obj", surface=10, seed=6)["points"])
    with pytest.raises(ValueError, match="sigma"):
        topovox.sample(meshes / "stanford-bunny.obj", near=10, sigma=0)


def test_the_command_line_writes_the_same_samples(tmp_path, meshes, cli):
    import subprocess, json, inspect
    out = tmp_path / "s.npz"
    r = subprocess.run(
        [cli, "sample", meshes / "suzanne.obj", "-o", out, "--surface", "500", "--near", "700", "--sigma", "0.02,0.1", "--uniform", "300", "--normalize", "unit-cube", "--seed", "9", "--json"],
        check=True, capture_output=True, text=True,
    )
    facts = json.loads(r.stdout)
    assert facts["points"] == 1500 and facts["surface"] == 500 and facts["sign"] in ("parity", "winding")
    z = np.load(out)
    py = topovox.sample(meshes / "suzanne.obj", surface=500, near=700, sigma=(0.02, 0.1), uniform=300, normalize="unit-cube", seed=9)
    assert np.array_equal(z["points"], py["points"].astype(np.float32))
    assert np.array_equal(z["sdf"], py["sdf"].astype(np.float32))
    assert np.array_equal(z["occupancy"], py["occupancy"]) and np.array_equal(z["kind"], py["kind"])
    assert np.array_equal(z["offset"], py["offset"]) and z["scale"] == py["scale"]
    # Every option of the one table is a keyword here and a flag there.
    params = inspect.signature(topovox.sample).parameters
    help_text = subprocess.run([cli, "sample", "--help"], check=True, capture_output=True, text=True).stdout
    for name, _help, _example in topovox._topovox.options("sample"):
        assert name in params, name
        assert "--" + name.replace("_", "-") in help_text, name
    # The input is never overwritten; bad values are one-line errors.
    r = subprocess.run([cli, "sample", meshes / "suzanne.obj", "-o", tmp_path / "x.npz", "--near", "5", "--sigma", "0"], capture_output=True, text=True)
    assert r.returncode == 2 and "sigma must be positive" in r.stderr and not (tmp_path / "x.npz").exists()


def test_batch_dask_and_the_cli_sample_folders_resumably(meshes, cli, tmp_path):
    from conftest import run_cli

    root = tmp_path / "in"
    (root / "sub").mkdir(parents=True)
    for name, where in [("cow.obj", root), ("teapot.obj", root / "sub")]:
        (where / name).write_bytes((meshes / name).read_bytes())
    kw = dict(surface=200, near=300, sigma=0.01, uniform=100, normalize="unit-sphere", seed=2)
    py_out, cli_out = tmp_path / "py", tmp_path / "cli"
    s = topovox.batch(root, py_out, run="sample", **kw)
    assert (s["done"], s["failed"]) == (2, 0), s
    run_cli(cli, "batch", root, "-o", cli_out, "--run", "sample", "--surface", 200, "--near", 300, "--sigma", 0.01, "--uniform", 100,
            "--normalize", "unit-sphere", "--seed", 2, "--quiet")
    for rel in ["cow.npz", "sub/teapot.npz"]:
        assert (py_out / rel).read_bytes() == (cli_out / rel).read_bytes(), rel
    one = topovox.sample(root / "cow.obj", **kw)
    z = np.load(py_out / "cow.npz")
    assert np.array_equal(z["sdf"], one["sdf"].astype(np.float32)) and np.array_equal(z["occupancy"], one["occupancy"])
    assert topovox.batch(root, py_out, run="sample", **kw)["skipped"] == 2
    with pytest.raises(FileExistsError, match="seed"):
        topovox.batch(root, py_out, run="sample", **dict(kw, seed=3))
    with pytest.raises(ValueError, match="npz"):
        topovox.batch(root, tmp_path / "y", run="sample", format="npy", **kw)
    pytest.importorskip("dask")
    import topovox.dask as vd

    bag = vd.voxelize_paths(root, tmp_path / "dask", run="sample", **kw)
    bag.compute(scheduler="synchronous")
    for rel in ["cow.npz", "sub/teapot.npz"]:
        assert (tmp_path / "dask" / rel).read_bytes() == (py_out / rel).read_bytes(), rel


def _srgb_to_linear(c):
    s = np.asarray(c, dtype=np.float64) / 255.0
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


def _linear_to_srgb(l):
    l = np.clip(l, 0.0, 1.0)
    return np.where(l <= 0.0031308, l * 12.92, 1.055 * l ** (1 / 2.4) - 0.055)


def test_surface_samples_carry_the_colour_at_their_point(tmp_path, cli):
    # A unit square of two triangles with a colour per corner (PLY), so
    # each surface point's colour is its corners' colours interpolated in
    # linear light, computed here from the point alone.
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
    rgb = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]])
    ply = tmp_path / "square.ply"
    lines = ["ply", "format ascii 1.0", "element vertex 4", "property float x", "property float y", "property float z",
             "property uchar red", "property uchar green", "property uchar blue", "element face 2",
             "property list uchar int vertex_indices", "end_header"]
    lines += [f"{x} {y} {z} {r} {g} {b}" for (x, y, z), (r, g, b) in zip(corners, rgb)]
    lines += ["3 0 1 2", "3 0 2 3"]
    ply.write_text("\n".join(lines) + "\n")
    s = topovox.sample(ply, surface=2000, near=50, sigma=0.1, uniform=50, seed=3, dtype=np.float64)
    c = s["colours"]
    assert c.shape == (2100, 3) and c.dtype == np.float32
    surf = s["kind"] == 0
    assert np.isnan(c[~surf]).all() and not np.isnan(c[surf]).any()
    x, y = s["points"][surf, 0], s["points"][surf, 1]
    lower = y <= x  # triangle (0, 1, 2): weights (1 - x, x - y, y); else (0, 2, 3): (1 - y, x, y - x)
    w = np.where(lower[:, None], np.stack([1 - x, x - y, y], 1), np.stack([1 - y, x, y - x], 1))
    lin = _srgb_to_linear(rgb)
    tri = np.where(lower[:, None, None], lin[[0, 1, 2]][None], lin[[0, 2, 3]][None])
    want = np.round(_linear_to_srgb(np.einsum("nc,nca->na", w, tri)) * 255) / 255
    # Points on the diagonal may take either triangle; elsewhere exact to a byte.
    off = np.abs(x - y) > 1e-9
    assert np.abs(c[surf][off] - want[off]).max() <= 1.0 / 255 + 1e-6
    assert np.mean(np.all(np.abs(c[surf][off] - want[off]) < 1e-6, axis=1)) > 0.99
    # The command line writes the same colours; a mesh without any has none.
    out = tmp_path / "s.npz"
    subprocess.run([cli, "sample", ply, "-o", out, "--surface", "2000", "--near", "50", "--sigma", "0.1", "--uniform", "50", "--seed", "3"], check=True, capture_output=True)
    assert np.array_equal(np.load(out)["colours"], c, equal_nan=True)
    v, f = corners, np.array([[0, 1, 2], [0, 2, 3]])
    assert "colours" not in topovox.sample(v, f, surface=10)


def test_textured_surface_samples_take_a_texel_of_their_point(meshes):
    from PIL import Image

    spot = meshes / "spot-textured.obj"
    s = topovox.sample(spot, surface=3000, seed=2)
    c = s["colours"]
    assert not np.isnan(c).any() and c.shape == (3000, 3)
    texels = np.asarray(Image.open(spot.parent / "spot_texture.png").convert("RGB")).reshape(-1, 3)
    known = {tuple(t) for t in np.unique(texels, axis=0)}
    got = np.round(c * 255).astype(np.uint8)
    # Nearest-texel lookup never invents a colour.
    assert all(tuple(g) in known for g in got)
    assert len(np.unique(got, axis=0)) > 20


def test_samples_come_in_float32_as_models_train_or_float64_when_asked(meshes):
    kw = dict(surface=50, near=60, sigma=0.02, uniform=40, seed=4)
    single = topovox.sample(meshes / "suzanne.obj", **kw)
    double = topovox.sample(meshes / "suzanne.obj", dtype=np.float64, **kw)
    for k in ("points", "sdf", "normals"):
        assert single[k].dtype == np.float32 and double[k].dtype == np.float64, k
        assert np.array_equal(single[k], double[k].astype(np.float32), equal_nan=True), k
    assert np.array_equal(single["occupancy"], double["occupancy"]) and single["offset"].dtype == np.float64
    with pytest.raises(ValueError, match="float32 or float64"):
        topovox.sample(meshes / "suzanne.obj", dtype=np.int32, **kw)
