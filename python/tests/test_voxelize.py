"""topovox from Python: the same voxels as the CLI, arrays in and out,
errors, the GIL, formats and checks."""

import json
import threading
import time

import numpy as np
import pytest

import topovox
from conftest import run_cli


@pytest.mark.parametrize(
    "mesh,mode,extra",
    [
        ("stanford-bunny.obj", "cover", []),
        ("stanford-bunny.obj", "sep26", []),
        ("cow.obj", "sep6", []),
        ("cow.obj", "ss6", []),
        ("fandisk.obj", "pos", []),
        ("cow.obj", "solid", []),
        ("suzanne.obj", "solid", ["--method", "winding"]),
        ("cow.obj", "solid+surface", ["--surface", "sep6"]),
        ("cow.obj", "solid", ["--fill", "flood", "--pad", "1"]),
        ("cow.obj", "solid", ["--hollow", "6"]),
        ("teapot.obj", "cover", ["--method", "reference"]),
        ("rocker-arm.obj", "sep6", ["--method", "scanline"]),
        ("cow.obj", "tunnel18", []),
        ("fandisk.obj", "tunnel26", []),
        ("cow.obj", "bubble", ["--seed", "5"]),
        ("stanford-bunny.obj", "diagonal", []),
    ],
)
def test_numpy_equals_the_cli_file(tmp_path, meshes, cli, mesh, mode, extra):
    out = tmp_path / "cli.npy"
    run_cli(cli, "voxelize", meshes / mesh, "-o", out, "--mode", mode, "--resolution", 64, "--quiet", *extra)
    want = np.load(out).astype(bool)
    kw = {}
    it = iter(extra)
    for flag in it:
        value = next(it, None) if flag != "--quiet" else None
        key = flag.lstrip("-").replace("-", "_")
        kw[key] = int(value) if key in ("pad", "hollow", "seed") else value
    got = topovox.voxelize(topovox.load_mesh(meshes / mesh), mode=mode, resolution=64, **kw)
    assert got.occupancy.shape == want.shape
    assert np.array_equal(got.occupancy, want), f"{mode} {extra}: {np.sum(got.occupancy != want)} voxels differ"
    assert got.count == int(want.sum())


def test_line_modes_equal_the_cli(tmp_path, cli):
    helix = topovox._topovox  # noqa: F841 - the module must be importable
    lines = pytest.importorskip("pathlib").Path(__file__).resolve().parents[2] / "examples" / "meshes" / "helix.lines"
    for mode in ("line6", "line26"):
        out = tmp_path / f"{mode}.npy"
        run_cli(cli, "voxelize", lines, "-o", out, "--mode", mode, "--resolution", 64, "--quiet")
        got = topovox.voxelize(topovox.load_mesh(lines), mode=mode, resolution=64)
        assert np.array_equal(got.occupancy, np.load(out).astype(bool)), mode


def test_explicit_grid_and_voxel_size_equal_the_cli(tmp_path, meshes, cli):
    out = tmp_path / "e.npy"
    run_cli(cli, "voxelize", meshes / "cow.obj", "-o", out, "--origin=-0.5,-0.2,-0.3", "--voxel-size", "0.02", "--dims", "40,30,20", "--quiet")
    got = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), origin=(-0.5, -0.2, -0.3), voxel_size=0.02, dims=(40, 30, 20))
    assert got.dims == (40, 30, 20)
    assert np.array_equal(got.occupancy, np.load(out).astype(bool))
    out2 = tmp_path / "v.npy"
    run_cli(cli, "voxelize", meshes / "cow.obj", "-o", out2, "--voxel-size", "0.03", "--pad", "2", "--quiet")
    got2 = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), voxel_size=0.03, pad=2)
    assert np.array_equal(got2.occupancy, np.load(out2).astype(bool))


def test_arrays_in_any_layout_and_dtype_give_the_same_voxels(meshes):
    m = topovox.load_mesh(meshes / "cow.obj")
    v, f = m.vertices, m.faces
    assert v.dtype == np.float64 and v.shape[1] == 3 and f.dtype == np.int64 and f.shape[1] == 3
    base = topovox.voxelize(v, f, resolution=48).occupancy
    assert np.array_equal(base, topovox.voxelize(m, resolution=48).occupancy)
    # Non-contiguous views (every column of a wider array, Fortran order).
    wide = np.zeros((len(v), 6))
    wide[:, ::2] = v
    assert not wide[:, ::2].flags["C_CONTIGUOUS"]
    assert np.array_equal(base, topovox.voxelize(wide[:, ::2], np.asfortranarray(f), resolution=48).occupancy)
    # int32 and uint32 faces.
    assert np.array_equal(base, topovox.voxelize(v, f.astype(np.int32), resolution=48).occupancy)
    assert np.array_equal(base, topovox.voxelize(v, f.astype(np.uint32), resolution=48).occupancy)
    # float32 vertices voxelize the float32 mesh (what a float32 array holds).
    v32 = v.astype(np.float32)
    assert np.array_equal(topovox.voxelize(v32, f, resolution=48).occupancy, topovox.voxelize(v32.astype(np.float64), f, resolution=48).occupancy)
    # Plain lists.
    tri = topovox.voxelize([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], resolution=4)
    assert tri.count > 0


@pytest.mark.parametrize(
    "vertices,faces,message",
    [
        (np.zeros((3, 2)), [[0, 1, 2]], r"vertices must have shape \(n, 3\); got \(3, 2\)"),
        (np.zeros((3,)), [[0, 1, 2]], "vertices must be a"),
        ([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]], [[0, 1, 2]], "vertex 2 has a non-finite coordinate"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, np.inf]], [[0, 1, 2]], "vertex 2 has a non-finite coordinate"),
        (np.eye(3), [[0, 1, 5]], "face 0 refers to vertex 5, but there are only 3 vertices"),
        (np.eye(3), [[0, 1, -1]], "face 0 refers to vertex -1"),
        (np.eye(3), [[0, 1]], r"faces must have shape \(n, 3\)"),
        (np.eye(3), [[0, 1, 2.5]], "integer vertex indices"),
        (np.eye(3), np.zeros((0, 3), np.int64), "no triangles|at least one"),
        (np.array([["a", "b", "c"]]), [[0, 0, 0]], "vertices must be"),
    ],
)
def test_bad_arrays_are_value_errors(vertices, faces, message):
    with pytest.raises(ValueError, match=message):
        topovox.voxelize(vertices, faces, resolution=8)


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"mode": "nope"}, "unknown mode"),
        ({"method": "magic"}, "unknown method"),
        ({"resolution": 0}, "resolution must be at least 1"),
        ({"resolution": 64, "voxel_size": 0.1}, "either resolution or voxel_size"),
        ({"origin": (0, 0, 0)}, "explicit grid needs all"),
        ({"voxel_size": -1.0}, "voxel size must be a positive"),
        ({"mode": "sep6", "method": "parity"}, "applies only to mode solid"),
        ({"mode": "cover", "hollow": 6}, "apply to mode solid"),
        ({"mode": "solid", "hollow": 7}, "unknown hollow connectivity \"7\" \\(expected one of: 6, 26\\)"),
        ({"threads": 0}, "threads must be at least 1"),
        ({"colour_rule": "mean"}, "unknown colour rule \"mean\""),
    ],
)
def test_bad_options_are_value_errors_in_python_terms(meshes, kwargs, message):
    m = topovox.load_mesh(meshes / "cow.obj")
    with pytest.raises(ValueError, match=message):
        topovox.voxelize(m, **kwargs)


def test_file_errors_are_os_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.obj: cannot read"):
        topovox.load_mesh(tmp_path / "missing.obj")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n")
    with pytest.raises(topovox.FileFormatError, match="bad.obj: .*line 4"):
        topovox.load_mesh(bad)
    assert issubclass(topovox.FileFormatError, OSError)
    with pytest.raises(OSError, match="unknown file extension"):
        topovox.load_mesh(tmp_path / "x.unknown")
    with pytest.raises(FileNotFoundError):
        topovox.load_voxels(tmp_path / "none.binvox")


def test_two_python_threads_voxelize_at_once(meshes):
    m = topovox.load_mesh(meshes / "stanford-bunny.obj")
    topovox.voxelize(m, resolution=64, threads=1)  # warm up (thread pool, page faults)
    spans = []

    def work():
        t0 = time.perf_counter()
        topovox.voxelize(m, mode="sep26", resolution=512, threads=1)
        spans.append((t0, time.perf_counter()))

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    (a0, a1), (b0, b1) = spans
    # With the GIL held the calls would run one after the other.
    assert max(a0, b0) < min(a1, b1), f"no overlap: {spans}"


def test_grid_properties_indices_and_helpers(meshes):
    g = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), resolution=32)
    occ = g.occupancy
    assert occ.dtype == np.bool_ and occ.shape == g.dims
    idx = g.indices()
    assert idx.dtype == np.int64 and np.array_equal(idx, np.argwhere(occ))
    assert len(g) == g.dims[0] and g.count == len(idx)
    centres = g.index_to_world(idx)
    assert np.array_equal(g.world_to_index(centres), idx)
    o, s = np.array(g.origin), g.voxel_size
    assert np.allclose(centres[0], o + (idx[0] + 0.5) * s)
    f = g.facts
    assert f["mode"] == "cover" and f["voxels"] == g.count and f["method"] in ("fast", "scanline")
    assert "VoxelGrid cover" in repr(g)


def test_attributes_colours_materials_normals_coverage(meshes, tmp_path, cli):
    spot = topovox.load_mesh(meshes / "spot-textured.obj")
    assert spot.uvs is not None and spot.uvs.shape == (len(spot.faces), 3, 2)
    assert spot.face_materials is not None and spot.materials[0]["texture"]
    g = topovox.voxelize(spot, resolution=48, attributes=True, normals=True)
    n = g.count
    assert g.colours.shape == (n, 3) and g.colours.dtype == np.uint8
    assert g.materials.shape == (n,) and g.normals.shape == (n, 3) and g.coverage.shape == (n,)
    assert topovox.voxelize(spot, resolution=48).colours is None
    # The colours are those the CLI writes into a coloured PLY point cloud.
    out = tmp_path / "spot.ply"
    run_cli(cli, "voxelize", meshes / "spot-textured.obj", "-o", out, "--resolution", 48, "--quiet")
    back = topovox.load_voxels(out)
    assert np.array_equal(back.indices(), g.indices())
    assert np.array_equal(back.colours, g.colours)


@pytest.mark.parametrize("fmt", ["vdb", "zarr", "vti"])
def test_attributes_saved_to_vdb_and_zarr_load_back(tmp_path, meshes, fmt):
    """Attributes carried in Python go into .vdb grids and Zarr arrays
    (as into .vti) and come back with load_voxels, value for value."""
    g = topovox.voxelize(topovox.load_mesh(meshes / "spot-textured.obj"), resolution=40, attributes=True, normals=True)
    p = tmp_path / f"spot.{fmt}"
    g.save(p)
    back = topovox.load_voxels(p)
    assert np.array_equal(back.indices(), g.indices())
    for name in ("colours", "materials", "normals", "coverage"):
        assert np.array_equal(getattr(back, name), getattr(g, name)), name
    plain = tmp_path / f"plain.{fmt}"
    topovox.voxelize(topovox.load_mesh(meshes / "spot-textured.obj"), resolution=40).save(plain)
    if fmt != "vti":
        assert topovox.load_voxels(plain).colours is None


@pytest.mark.parametrize("fmt", ["npy", "npy-bool", "npz", "binvox", "vox", "txt", "schem", "vti", "ply", "vdb", "zarr"])
def test_save_and_load_every_voxel_format(tmp_path, meshes, fmt):
    g = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), resolution=40)
    ext = "npy" if fmt == "npy-bool" else fmt
    p = tmp_path / f"cow.{ext}"
    g.save(p, format=fmt)
    back = topovox.load_voxels(p)
    occ = back.occupancy
    # binvox pads to a cube; the others keep the dims.
    assert np.array_equal(occ[: g.dims[0], : g.dims[1], : g.dims[2]], g.occupancy)
    assert back.count == g.count


@pytest.mark.parametrize("fmt", ["obj", "glb"])
def test_save_meshes_of_the_voxels(tmp_path, meshes, fmt):
    g = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), resolution=24)
    p = tmp_path / f"cow.{fmt}"
    g.save(p)
    assert p.stat().st_size > 0
    back = topovox.voxelize(topovox.load_mesh(p), mode="solid", origin=g.origin, voxel_size=g.voxel_size, dims=g.dims)
    assert np.array_equal(back.occupancy, g.occupancy)


def test_save_refuses_unknown_formats_and_missing_folders(tmp_path, meshes):
    g = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), resolution=16)
    with pytest.raises(ValueError, match="cannot tell the output format"):
        g.save(tmp_path / "x.unknown")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        g.save(tmp_path / "no" / "x.npy")


def test_check_matches_the_cli_report(tmp_path, meshes, cli):
    m = topovox.load_mesh(meshes / "cow.obj")
    g = topovox.voxelize(m, mode="sep6", resolution=64)
    report = g.check(m)
    assert report["closed"] and report["separating_6"] and report["tunnels_6"] == 0
    p = tmp_path / "cow.npy"
    g.save(p)
    cli_report = json.loads(run_cli(cli, "check", p, "--mesh", meshes / "cow.obj", "--resolution", 64, "--json").stdout)
    for k in ("voxels", "components_6", "components_26", "separating_6", "separating_26", "thin_removable", "tunnels_6", "tunnels_26"):
        assert report[k] == cli_report[k], k
    assert g.check()["components_26"] == cli_report["components_26"]


def test_check_of_a_tiled_grid_runs_window_by_window(meshes):
    m = topovox.load_mesh(meshes / "cow.obj")
    dense = topovox.voxelize(m, mode="sep6", resolution=64).check(m)
    tiled = topovox.voxelize(m, mode="sep6", resolution=64, tile=16).check(m)
    assert (dense["sparse"], tiled["sparse"]) == (False, True) and tiled["windows"] >= 1
    for k, v in dense.items():
        if k not in ("sparse", "windows"):
            assert tiled[k] == v, k


def test_trimesh_in_and_out(meshes):
    trimesh = pytest.importorskip("trimesh")
    tm = trimesh.load(meshes / "cow.obj", process=False, force="mesh")
    ours = topovox.load_mesh(meshes / "cow.obj")
    assert np.array_equal(topovox.voxelize(tm, resolution=48).occupancy, topovox.voxelize(ours, resolution=48).occupancy)
    g = topovox.voxelize(ours, mode="solid", resolution=32)
    out = g.to_trimesh_mesh()
    assert isinstance(out, trimesh.Trimesh)
    # The quads bound exactly the set voxels: the enclosed volume is theirs.
    assert abs(out.volume - g.count * g.voxel_size**3) < 1e-9 * max(1.0, g.count * g.voxel_size**3)
    coloured = topovox.voxelize(topovox.load_mesh(meshes / "spot-textured.obj"), resolution=24, attributes=True).to_trimesh_mesh()
    assert coloured.visual.face_colors.shape[1] == 4


def test_mesh_from_arrays_and_properties(meshes):
    m = topovox.Mesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[0, 1, 2], [0, 1, 3]]))
    assert m.vertices.shape == (4, 3) and m.faces.shape == (2, 3) and m.segments.shape == (0, 2)
    assert m.path is None and m.vertex_colours is None and m.uvs is None
    assert np.array_equal(m.bounds, [[0, 0, 0], [1, 1, 1]])
    help_text = topovox.voxelize.__doc__
    assert "resolution" in help_text and "mode" in help_text


def test_tiled_runs_give_the_same_voxels(meshes):
    m = topovox.load_mesh(meshes / "stanford-bunny.obj")
    for mode in ["cover", "sep6", "bubble"]:
        a = topovox.voxelize(m, mode=mode, resolution=150)
        b = topovox.voxelize(m, mode=mode, resolution=150, tile=64, max_memory="2G")
        assert b.facts["method"] == "tiled" and b.facts["tile"] == 64
        assert np.array_equal(a.indices(), b.indices())
    lines = pytest.importorskip("pathlib").Path(__file__).resolve().parents[2] / "examples" / "meshes" / "helix.lines"
    helix = topovox.load_mesh(lines)
    for mode in ["line6", "line26"]:
        a = topovox.voxelize(helix, mode=mode, resolution=100)
        b = topovox.voxelize(helix, mode=mode, resolution=100, tile=16)
        assert b.facts["method"] == "tiled" and b.facts["tile"] == 16
        assert a.count > 100 and np.array_equal(a.indices(), b.indices()), mode
    with pytest.raises(ValueError, match="multiple of 8"):
        topovox.voxelize(m, tile=12)
    with pytest.raises(ValueError, match="not a size|unknown unit"):
        topovox.voxelize(m, max_memory="lots")
