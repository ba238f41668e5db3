"""What a new user and a data-loader user ran into (issue 53): calls that
cost what their work costs, and the habits NumPy users bring."""

import os
import pathlib
import statistics
import time

import numpy as np

import topovox

TETRA = (
    np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float),
    np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
)


def median_seconds(call, n=21):
    call()
    times = []
    for _ in range(n):
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def test_a_small_call_returns_as_soon_as_its_work_is_done(tmp_path):
    # The work is well under a millisecond. The caller used to park for
    # the whole 50 ms signal poll after the worker had already finished:
    # medians of 50 ms. The bound is far above the work and far below the
    # poll, so a loaded machine does not fail it and the old wait does.
    mesh = topovox.as_mesh(*TETRA)
    g = topovox.voxelize(mesh, resolution=16)
    for name, call in {
        "voxelize": lambda: topovox.voxelize(mesh, resolution=16),
        "voxelize threads=2": lambda: topovox.voxelize(mesh, resolution=16, threads=2),
        "sdf": lambda: topovox.sdf(mesh, resolution=16),
        "save": lambda: g.save(tmp_path / "g.npy"),
    }.items():
        seconds = median_seconds(call)
        assert seconds < 0.025, f"{name}: median {seconds * 1000:.1f} ms"


def test_the_maps_take_lists_tuples_and_single_points():
    g = topovox.voxelize(*TETRA, resolution=8)
    # The docstring's own example, and what NumPy users pass.
    assert g.world_to_index([[0.0, 0.0, 0.0]]).tolist() == [list(g.world_to_index(np.zeros((1, 3)))[0])]
    assert g.world_to_index((0.5, 0.5, 0.5)).shape == (3,)
    assert g.world_to_index([(0, 0, 0), (1, 1, 1)]).dtype == np.int64
    assert np.array_equal(g.world_to_index(np.zeros((2, 3), np.float32)), g.world_to_index([[0, 0, 0]] * 2))
    centre = g.index_to_world([1, 2, 3])
    assert centre.shape == (3,) and np.allclose(centre, g.origin + (np.array([1, 2, 3]) + 0.5) * g.spacing)
    assert np.array_equal(g.index_to_world(g.coords()), g.index_to_world(g.coords().tolist()))
    assert np.array_equal(g.world_to_index(g.index_to_world(g.coords())), g.coords())
    import pytest

    for bad, message in [([[1.0, 2.0]], r"points must have shape \(n, 3\) or \(3,\); got \(1, 2\)"), ("abc", "points must be numbers")]:
        with pytest.raises(ValueError, match=message):
            g.world_to_index(bad)
    with pytest.raises(ValueError, match="indices must be integers"):
        g.index_to_world([[0.5, 0.0, 0.0]])


def test_grids_from_arrays_take_the_grids_own_placement():
    import pytest

    g = topovox.voxelize(*TETRA, voxel_size=(0.1, 0.2, 0.3))
    again = topovox.VoxelGrid.from_dense(g.to_dense(), origin=g.origin, voxel_size=g.voxel_size)
    assert again.count == g.count and np.array_equal(again.origin, g.origin) and again.voxel_size == g.voxel_size
    listed = topovox.VoxelGrid.from_coords(g.coords(), list(g.dims), origin=list(g.origin), voxel_size=g.voxel_size)
    assert np.array_equal(listed.coords(), g.coords())
    also = topovox.VoxelGrid.from_coords(g.coords(), np.array(g.dims), origin=tuple(g.origin))
    assert also.dims == g.dims and also.voxel_size == 1.0
    with pytest.raises(ValueError, match="dims must be 3 integers"):
        topovox.VoxelGrid.from_coords(g.coords(), (8.5, 9, 9))
    with pytest.raises(ValueError, match="origin must be 3 numbers"):
        topovox.VoxelGrid.from_dense(g.to_dense(), origin=(0, 0))
    import inspect

    for f in (topovox.VoxelGrid.from_dense, topovox.VoxelGrid.from_coords):
        assert "voxel_size=1.0" in str(inspect.signature(f)), inspect.signature(f)


PLACEMENT = ["dims", "shape", "origin", "bounds", "voxel_size", "spacing", "world_to_index", "index_to_world"]


def test_distance_grids_have_the_voxel_grids_placement():
    mesh = topovox.as_mesh(*TETRA)
    grid = dict(origin=(-0.5, -0.25, 0.0), voxel_size=(0.25, 0.25, 0.5), dims=(8, 7, 4))
    g = topovox.voxelize(mesh, **grid)
    d = topovox.sdf(mesh, **grid)
    for name in PLACEMENT:
        assert hasattr(topovox.DistanceGrid, name) and hasattr(topovox.VoxelGrid, name), name
        a, b = getattr(g, name), getattr(d, name)
        if callable(a):
            arg = [[1, 2, 3]] if name == "index_to_world" else [[0.3, 0.2, 0.1]]
            a, b = a(arg), b(arg)
        assert np.array_equal(np.asarray(a), np.asarray(b)), (name, a, b)


def test_a_link_to_nothing_is_one_bad_input_not_the_batchs_end(tmp_path, cli):
    import json
    import os
    import pathlib
    import subprocess

    box = pathlib.Path(__file__).resolve().parents[2] / "examples" / "meshes" / "box.obj"
    ds = tmp_path / "ds"
    (ds / "sub").mkdir(parents=True)
    (ds / "good.obj").write_bytes(box.read_bytes())
    os.symlink(tmp_path / "gone.obj", ds / "sub" / "broken.obj")
    os.symlink(tmp_path / "gone-folder", ds / "sub" / "broken-folder")
    s = topovox.batch(ds, tmp_path / "py", resolution=8)
    assert (s["done"], s["failed"]) == (1, 1), s
    assert any("broken-folder" in w and "link to nothing" in w for w in s["warnings"]), s
    records = [json.loads(line) for line in (tmp_path / "py" / "manifest.jsonl").read_text().splitlines()]
    failed = [r for r in records if r.get("error")]
    assert len(failed) == 1 and failed[0]["input"].endswith("broken.obj"), records
    r = subprocess.run([str(cli), "batch", str(ds), "-o", str(tmp_path / "cli"), "--resolution", "8"], capture_output=True, text=True)
    assert "cannot list" not in r.stderr, r.stderr
    assert (tmp_path / "cli" / "good.npy").exists(), (r.returncode, r.stderr)
    assert "broken-folder" in r.stderr, r.stderr


def test_a_successful_vox_run_says_nothing_on_stderr(tmp_path, cli):
    import pathlib
    import subprocess

    box = pathlib.Path(__file__).resolve().parents[2] / "examples" / "meshes" / "box.obj"
    r = subprocess.run([str(cli), "voxelize", str(box), "-o", str(tmp_path / "box.vox"), "--resolution", "8"], capture_output=True, text=True)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "no colours" in r.stdout, r.stdout


def test_a_file_in_place_of_the_output_folder_is_not_a_directory(tmp_path):
    import pathlib

    import pytest

    box = pathlib.Path(__file__).resolve().parents[2] / "examples" / "meshes" / "box.obj"
    (tmp_path / "out").write_text("a file the user keeps")
    with pytest.raises(NotADirectoryError, match="a file stands there"):
        topovox.batch([box], tmp_path / "out", resolution=8)
    assert (tmp_path / "out").read_text() == "a file the user keeps"


class _Tensor:
    def __init__(self, a):
        self.a = np.asarray(a)

    def cpu(self):
        return self

    def numpy(self):
        return self.a


def test_open3d_tensor_meshes_are_meshes():
    import pytest

    v, f = TETRA
    want = topovox.voxelize(v, f, resolution=8)

    class TensorMeshLike:  # the attributes an open3d.t.geometry.TriangleMesh has
        vertex = {"positions": _Tensor(v.astype(np.float32)), "colors": _Tensor(np.full((4, 3), 0.5, np.float32))}
        triangle = {"indices": _Tensor(f.astype(np.int32))}

    m = topovox.as_mesh(TensorMeshLike())
    assert (m.vertex_colours == 128).all() and np.array_equal(m.faces, f)
    assert np.array_equal(topovox.voxelize(TensorMeshLike(), resolution=8).coords(), want.coords())
    try:
        import open3d as o3d
    except ImportError:
        return
    real = o3d.t.geometry.TriangleMesh()
    real.vertex.positions = o3d.core.Tensor(v)
    real.triangle.indices = o3d.core.Tensor(f.astype(np.int64))
    assert np.array_equal(topovox.voxelize(real, resolution=8).coords(), want.coords())
    with pytest.raises(ValueError, match="triangle.indices"):
        topovox.as_mesh(o3d.t.geometry.TriangleMesh())


def _margin(occ, pad):
    inner = np.zeros_like(occ)
    inner[pad:-pad, pad:-pad, pad:-pad] = True
    return occ & ~inner


def test_pad_is_an_empty_margin_in_every_mode():
    import pathlib

    examples = pathlib.Path(__file__).resolve().parents[2] / "examples" / "meshes"
    cube = topovox.load_mesh(examples / "box.obj")
    rng = np.random.default_rng(7)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    tilted = topovox.as_mesh(TETRA[0] @ q.T, TETRA[1])
    lines = topovox.load_mesh(examples / "helix.lines")
    surface_modes = [m for m in topovox.MODES if m not in ("line6", "line26")]
    cases = [(m, mesh) for m in surface_modes for mesh in (cube, tilted)] + [(m, lines) for m in ("line6", "line26")]
    for mode, mesh in cases:
        for grid in (dict(resolution=8), dict(resolution=5, fit="cube"), dict(voxel_size=0.25), dict(voxel_size=(0.25, 0.5, 0.125), fit="cube")):
            for pad in (1, 2):
                g = topovox.voxelize(mesh, mode=mode, pad=pad, **grid)
                occ = g.to_dense()
                # A solid may have no voxel centre in a one-voxel interior,
                # and a curve strictly inside one voxel meets none of line6's
                # or line26's targets; every surface mode sets something.
                assert occ.any() or mode in ("solid", "line6", "line26"), (mode, grid, pad)
                assert not _margin(occ, pad).any(), (mode, grid, pad, np.argwhere(_margin(occ, pad))[:4])


def test_batch_reports_progress_to_a_callback_and_on_stderr(tmp_path):
    import pathlib
    import subprocess
    import sys

    import pytest

    box = pathlib.Path(__file__).resolve().parents[2] / "examples" / "meshes" / "box.obj"
    ds = tmp_path / "ds"
    ds.mkdir()
    for n in range(5):
        (ds / f"m{n}.obj").write_bytes(box.read_bytes())
    seen = []
    s = topovox.batch(ds, tmp_path / "out", resolution=8, jobs=1, progress=lambda done, total: seen.append((done, total)))
    assert s["done"] == 5 and seen and seen[-1] == (5, 5), seen
    assert all(t == 5 for _, t in seen) and [d for d, _ in seen] == sorted(d for d, _ in seen), seen
    # A rerun: everything skipped counts as finished at once.
    seen.clear()
    topovox.batch(ds, tmp_path / "out", resolution=8, progress=lambda done, total: seen.append((done, total)))
    assert seen == [(5, 5)], seen

    def stop(done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        topovox.batch(ds, tmp_path / "out2", resolution=8, progress=stop)
    code = f"import topovox; topovox.batch({str(ds)!r}, {str(tmp_path / 'out3')!r}, resolution=8, progress=True)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0 and "5/5 meshes" in r.stderr, r.stderr


def test_grids_compare_by_voxels_and_place_not_identity():
    import pickle

    mesh = topovox.as_mesh(*TETRA)
    a, b = topovox.voxelize(mesh, resolution=8), topovox.voxelize(mesh, resolution=8)
    assert a is not b and a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert pickle.loads(pickle.dumps(a)) == a
    assert topovox.VoxelGrid.from_dense(a.to_dense(), origin=a.origin, voxel_size=a.voxel_size) == a
    assert a != topovox.voxelize(mesh, resolution=8, mode="sep6")
    moved = topovox.VoxelGrid.from_dense(a.to_dense(), origin=a.origin + 1, voxel_size=a.voxel_size)
    assert a != moved and a != "a grid" and a != None  # noqa: E711
    f, g = topovox.sdf(mesh, resolution=8), topovox.sdf(mesh, resolution=8)
    assert f == g and hash(f) == hash(g)
    assert f != topovox.sdf(mesh, resolution=8, band=2) and f != topovox.sdf(mesh, resolution=8, unsigned=True)


def test_a_rerun_retries_a_failed_mesh_without_piling_up_its_lines(tmp_path, cli):
    import json
    import pathlib
    import subprocess

    box = pathlib.Path(__file__).resolve().parents[2] / "examples" / "meshes" / "box.obj"
    ds = tmp_path / "ds"
    ds.mkdir()
    (ds / "good.obj").write_bytes(box.read_bytes())
    (ds / "bad.obj").write_text("v 0 0 0\nf 1 2 3\n")
    lines = lambda: [json.loads(x) for x in (tmp_path / "out" / "manifest.jsonl").read_text().splitlines()]  # noqa: E731
    for _ in range(3):
        s = topovox.batch(ds, tmp_path / "out", resolution=8)
        assert s["failed"] == 1, s
    subprocess.run([str(cli), "batch", str(ds), "-o", str(tmp_path / "out"), "--resolution", "8"], capture_output=True)
    assert [r["status"] for r in lines()] in (["done", "failed"], ["failed", "done"]), lines()
    # Once it reads, the mesh is done and recorded so.
    (ds / "bad.obj").write_bytes(box.read_bytes())
    assert topovox.batch(ds, tmp_path / "out", resolution=8)["done"] == 1
    assert [r["status"] for r in lines()][-1] == "done"


def test_modelnet_off_files_are_meshes(tmp_path):
    v, f = TETRA
    rows = "\n".join(" ".join(map(str, p)) for p in v)
    faces = "\n".join("3 " + " ".join(map(str, t)) for t in f)
    # ModelNet's quirk: the keyword run into the counts.
    (tmp_path / "t.off").write_text(f"OFF{len(v)} {len(f)} 0\n{rows}\n{faces}\n")
    m = topovox.load_mesh(tmp_path / "t.off")
    assert np.array_equal(m.vertices, v) and np.array_equal(m.faces, f)
    assert topovox.voxelize(tmp_path / "t.off", resolution=8, mode="sep6") == topovox.voxelize(v, f, resolution=8, mode="sep6")
    s = topovox.batch(tmp_path, tmp_path / "out", resolution=8)
    assert s["done"] == 1 and (tmp_path / "out" / "t.npy").exists()


def test_distance_grids_pickle_and_deep_copy():
    import copy
    import pickle

    import pytest

    mesh = topovox.as_mesh(*TETRA)
    for kw in (dict(resolution=12), dict(resolution=12, band="all"), dict(resolution=12, unsigned=True), dict(voxel_size=(0.1, 0.05, 0.2), band=2)):
        f = topovox.sdf(mesh, **kw)
        g = pickle.loads(pickle.dumps(f))
        assert g == f and g.facts == f.facts and g.signed == f.signed, kw
        assert np.array_equal(g.to_dense(), f.to_dense()) and np.array_equal(g.coords(), f.coords())
        assert copy.deepcopy(f) == f
    # A damaged state is a ValueError, never a crash.
    ctor, (state,) = f.__reduce__()
    state["values"] = state["values"][:-1]
    with pytest.raises(ValueError, match="not a DistanceGrid state"):
        ctor(state)


def test_format_is_one_named_choice_everywhere(tmp_path, cli):
    import subprocess

    import pytest

    assert topovox.FORMATS[:2] == ("npy", "npy-bool") and "glb" in topovox.FORMATS and "obj" in topovox.FORMATS
    g = topovox.voxelize(*TETRA, resolution=4)
    g.save(tmp_path / "x.dat", format="NPY")
    assert (tmp_path / "x.dat").read_bytes()[:6] == b"\x93NUMPY"
    with pytest.raises(ValueError, match='unknown format "nope" \\(expected one of: npy, npy-bool'):
        g.save(tmp_path / "y.npy", format="nope")
    # The CLI lists every format with its help, from the same list.
    h = subprocess.run([str(cli), "voxelize", "--help"], capture_output=True, text=True).stdout
    for name in topovox.FORMATS:
        assert f"  {name}" in h or f" {name}:" in h, (name, h[-2000:])
    r = subprocess.run([str(cli), "batch", str(tmp_path), "-o", str(tmp_path / "o"), "--format", "nope"], capture_output=True, text=True)
    assert r.returncode == 2 and "nope" in r.stderr and "npy-bool" in r.stderr, r.stderr


def test_a_clone_without_the_shared_folder_fetches_the_test_meshes_checked(tmp_path, meshes):
    # Issue 53.4: the test command needed ../shared beside the clone. The
    # script fetches the ten collection meshes (here from the shared folder
    # through file://) and checks each one's SHA-256; a changed file fails
    # in one line and leaves nothing.
    import shutil
    import subprocess

    script = pathlib.Path(__file__).resolve().parents[2] / "scripts" / "test-meshes.sh"
    env = dict(os.environ, TOPOVOX_MESH_BASE=meshes.as_uri())
    r = subprocess.run(["bash", str(script), str(tmp_path / "good")], env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    got = sorted(p.name for p in (tmp_path / "good" / "meshes").iterdir())
    assert got == sorted(p.name for p in meshes.iterdir() if p.name != "README.md")
    for name in got:
        assert (tmp_path / "good" / "meshes" / name).read_bytes() == (meshes / name).read_bytes(), name
    bad = tmp_path / "bad-source"
    shutil.copytree(meshes, bad)
    with open(bad / "teapot.obj", "a") as f:
        f.write("# changed\n")
    env["TOPOVOX_MESH_BASE"] = bad.as_uri()
    r = subprocess.run(["bash", str(script), str(tmp_path / "bad")], env=env, capture_output=True, text=True)
    assert r.returncode == 1 and "teapot.obj" in r.stderr and "SHA-256" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "bad").exists() and not list(tmp_path.glob("bad.part-*"))
