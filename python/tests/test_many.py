"""Training batches (issue 57): voxelize_many's items equal single calls bit
for bit, the features equal what voxelize and the queries give, the
layouts follow each library's documented order, bad meshes fail with
their index or are skipped, and the data loader's pieces (Dataset,
collate) give the same batch."""

import inspect
import multiprocessing
import pathlib
import pickle
import re

import numpy as np
import pytest

import topovox
import topovox.torch as ttorch

REPO = pathlib.Path(__file__).resolve().parents[2]
NAMES = ["stanford-bunny.obj", "teapot.obj", "fandisk.obj", "beetle.obj", "suzanne.obj", "spot-textured.obj"]


def rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def rotated(meshes, seed):
    """Randomly rotated and scaled (vertices, faces) pairs of the shared meshes."""
    rng = np.random.default_rng(seed)
    out = []
    for n in NAMES[:-1]:
        m = topovox.load_mesh(meshes / n)
        out.append((np.asarray(m.vertices) @ rotation(int(rng.integers(1 << 30))).T * rng.uniform(0.1, 10), np.asarray(m.faces)))
    return out


@pytest.mark.parametrize("mode", ["cover", "solid", "sep6"])
@pytest.mark.parametrize("resolution", [32, 64])
def test_items_equal_single_calls_bit_for_bit(meshes, mode, resolution):
    items = rotated(meshes, resolution) + [topovox.load_mesh(meshes / NAMES[-1])]
    batch = topovox.voxelize_many(items, mode=mode, resolution=resolution)
    assert batch.coords.dtype == np.int32 and batch.coords.flags.c_contiguous
    assert batch.features.dtype == np.float32 and batch.columns == ("occupancy",)
    assert len(batch) == len(items) and batch.offsets[0] == 0 and batch.offsets[-1] == len(batch.coords)
    # Sorted by batch, then C order.
    keys = batch.coords.astype(np.int64)
    flat = ((keys[:, 0] * resolution + keys[:, 1]) * resolution + keys[:, 2]) * resolution + keys[:, 3]
    assert np.all(np.diff(flat) > 0)
    for b, m in enumerate(items):
        one = topovox.voxelize(*m, mode=mode, resolution=resolution, fit="cube") if isinstance(m, tuple) else topovox.voxelize(m, mode=mode, resolution=resolution, fit="cube")
        assert np.array_equal(np.asarray(batch.item(b)), np.asarray(one)), b
        ijk, feats = batch.rows(b)
        assert np.array_equal(ijk, np.argwhere(np.asarray(one))), b
        assert np.all(batch.coords[batch.offsets[b] : batch.offsets[b + 1], 0] == b)
        assert np.all(feats == 1)
        assert np.array_equal(batch.origins[b], one.origin) and np.array_equal(batch.voxel_sizes[b], one.spacing)
    dense = batch.to_dense()
    assert dense.shape == (len(items), resolution, resolution, resolution)
    assert all(np.array_equal(dense[b], np.asarray(batch.item(b))) for b in range(len(items)))


def test_features_equal_the_attributes_and_the_queries(meshes):
    spot = topovox.load_mesh(meshes / "spot-textured.obj")
    bunny = topovox.load_mesh(meshes / "stanford-bunny.obj")
    names = ("occupancy", "normal", "color", "coverage", "material", "sdf")
    for mode in ("cover", "solid"):
        batch = topovox.voxelize_many([spot, bunny], features=names, mode=mode, resolution=40)
        assert batch.columns[:4] == ("occupancy", "normal.x", "normal.y", "normal.z") and batch.columns[-1] == "sdf"
        assert batch.features.shape[1] == 10
        for b, m in enumerate((spot, bunny)):
            one = topovox.voxelize(m, mode=mode, resolution=40, fit="cube", attributes=True)
            _, f = batch.rows(b)
            assert np.array_equal(f[:, 1:4], one.normals)
            # A mesh without colours gets the renderer's grey.
            colours = one.colours if b == 0 else np.full((len(f), 3), 200, np.uint8)
            assert one.colours is not None or b == 1
            assert np.array_equal(f[:, 4:7], colours.astype(np.float32) / np.float32(255))
            assert np.array_equal(f[:, 7], one.coverage)
            materials = one.materials if one.materials is not None else np.full(len(f), -1)
            assert np.array_equal(f[:, 8], materials.astype(np.float32))
            q = topovox.Query(m)
            centres = one.index_to_world(one.indices())
            want = q.distance(centres).astype(np.float32)
            assert np.array_equal(f[:, 9].view(np.uint32), want.view(np.uint32))
            assert np.array_equal(f[:, 9] < 0, q.contains(centres))
    # The sdf column is `topovox sdf --band all` at those voxels.
    field = np.asarray(topovox.sdf(bunny, resolution=40, fit="cube", band="all"))
    batch = topovox.voxelize_many([bunny], features="sdf", mode="solid", resolution=40)
    i, j, k = batch.rows(0)[0].T
    assert np.array_equal(batch.features[:, 0].view(np.uint32), field[i, j, k].view(np.uint32))
    dense = batch.to_dense(features=True)
    assert dense.shape == (1, 1, 40, 40, 40) and np.array_equal(dense[0, 0, i, j, k], batch.features[:, 0])


def test_box_grids_and_sparse_items_in_c_order(meshes):
    """fit="box" (dims differ per axis), a voxel size per axis, and a tiled
    (sparse) item: rows in C order as NumPy's argwhere gives them."""
    items = rotated(meshes, 11)[:3]
    for kw in (dict(fit="box", resolution=45), dict(fit="box", voxel_size=(0.03, 0.05, 0.02)), dict(fit="box", resolution=40, tile=16)):
        scale = [np.ptp(v, axis=0).max() for v, _ in items]
        its = [(v / s, f) for (v, f), s in zip(items, scale)]
        batch = topovox.voxelize_many(its, **kw)
        for b, m in enumerate(its):
            one = topovox.voxelize(*m, **kw)
            assert np.array_equal(batch.rows(b)[0], np.argwhere(np.asarray(one))), (kw, b)
            assert tuple(batch.dims[b]) == one.dims
        assert batch.to_dense().shape[1:] == tuple(batch.dims.max(axis=0))


def test_the_same_batch_on_any_thread_count(meshes):
    items = rotated(meshes, 7)
    a = topovox.voxelize_many(items, resolution=48, mode="solid", features=("occupancy", "normal", "sdf"), threads=1)
    b = topovox.voxelize_many(items, resolution=48, mode="solid", features=("occupancy", "normal", "sdf"), threads=2)
    assert np.array_equal(a.coords, b.coords) and np.array_equal(a.offsets, b.offsets)
    assert np.array_equal(a.features.view(np.uint32), b.features.view(np.uint32))


def test_layouts_follow_each_librarys_order(meshes):
    batch = topovox.voxelize_many(rotated(meshes, 3)[:3], resolution=32, features=("occupancy", "normal"))
    b, i, j, k = batch.coords.T
    s = batch.layout("spconv")
    assert s["indices"].dtype == np.int32 and s["indices"].flags.c_contiguous
    assert np.array_equal(s["indices"], np.stack([b, k, j, i], axis=1)) and s["spatial_shape"] == [32, 32, 32]
    assert s["batch_size"] == 3 and s["features"] is batch.features
    t = batch.layout("torchsparse")
    assert np.array_equal(t["coords"], np.stack([b, i, j, k], axis=1)) and t["coords"].dtype == np.int32
    m = batch.layout("minkowski")
    assert np.array_equal(m["coordinates"], np.stack([b, i, j, k], axis=1)) and "features" in m
    f = batch.layout("fvdb")
    assert np.array_equal(f["ijk"], np.stack([i, j, k], axis=1)) and np.array_equal(f["joffsets"], batch.offsets)
    # fVDB's origin is the world position of voxel (0, 0, 0)'s centre.
    for n in range(3):
        assert np.allclose(f["origins"][n], batch.item(n).index_to_world(np.zeros((1, 3), int))[0])
    o = batch.layout("ocnn")
    # O-CNN quantizes a point p in [-1, 1] at depth d to floor((p + 1) * 2**(d - 1)).
    assert o["depth"] == 5 and o["points"].dtype == np.float32
    assert np.all(np.abs(o["points"]) < 1)
    assert np.array_equal(np.floor((o["points"] + 1) * 2 ** (o["depth"] - 1)).astype(int), np.stack([i, j, k], axis=1))
    assert np.array_equal(o["batch_id"][:, 0], b.astype(np.float32))
    with pytest.raises(ValueError, match="unknown layout"):
        batch.layout("nope")


def test_a_broken_mesh_fails_with_its_index_or_is_skipped(meshes, tmp_path):
    bad = tmp_path / "broken.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
    good = [meshes / "teapot.obj", meshes / "fandisk.obj"]
    items = [good[0], tmp_path / "missing.obj", bad, good[1]]
    with pytest.raises(FileNotFoundError, match=r"mesh 1: .*missing\.obj"):
        topovox.voxelize_many(items, resolution=32)
    with pytest.raises(topovox.FileFormatError, match=r"mesh 1: .*broken\.obj: face 0 refers to vertex 8"):
        topovox.voxelize_many([good[0], bad], resolution=32)
    batch = topovox.voxelize_many(items, resolution=32, on_error="skip")
    assert sorted(batch.errors) == [1, 2] and "missing.obj" in batch.errors[1] and "broken.obj" in batch.errors[2]
    assert batch.offsets[1] == batch.offsets[2] == batch.offsets[3]
    with pytest.raises(ValueError, match="broken.obj"):  # the item's error
        batch.item(2)
    alone = topovox.voxelize_many(good, resolution=32)
    assert np.array_equal(batch.rows(3)[0], alone.rows(1)[0]) and np.array_equal(batch.rows(0)[0], alone.rows(0)[0])
    nothing = (np.zeros((3, 3)), np.zeros((0, 3), int))
    with pytest.raises(ValueError, match=r"mesh 1 \(tuple\): contains no triangles"):
        topovox.voxelize_many([good[0], nothing], resolution=32)
    assert list(topovox.voxelize_many([nothing, good[0]], resolution=32, on_error="skip").errors) == [0]
    # A mesh that loads but fails to voxelize is named the same way.
    lines = topovox.Mesh(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], float), segments=np.array([[0, 1], [1, 2]]))
    with pytest.raises(ValueError, match=r"^mesh 1: mesh: has only line segments"):
        topovox.voxelize_many([good[0], lines], resolution=32)
    kept = topovox.voxelize_many([good[0], lines], resolution=32, on_error="skip")
    assert list(kept.errors) == [1] and kept.errors[1].startswith("mesh 1: mesh: has only line segments")
    with pytest.raises(ValueError, match="on_error"):
        topovox.voxelize_many(good, on_error="ignore")
    with pytest.raises(ValueError, match="unknown feature"):
        topovox.voxelize_many(good, features=("occupancy", "curvature"))
    with pytest.raises(TypeError, match="list of meshes"):
        topovox.voxelize_many(good[0])
    with pytest.raises(RuntimeError, match="more than the"):
        topovox.voxelize_many(good * 8, resolution=64, mode="solid", max_memory="1M")
    empty = topovox.voxelize_many([], resolution=32)
    assert len(empty) == 0 and empty.coords.shape == (0, 4) and empty.offsets.tolist() == [0]


def test_takes_every_option_voxelize_takes():
    single = set(inspect.signature(topovox.voxelize).parameters) - {"mesh_or_vertices", "faces"}
    many = set(inspect.signature(topovox.voxelize_many).parameters)
    assert single <= many
    assert set(topovox.FEATURES) == {"occupancy", "normal", "colour", "coverage", "material", "sdf"}


def _getitem(args):
    data, n = args
    return data[n]


def test_the_dataset_and_collate_give_the_batch(meshes, tmp_path):
    for n in NAMES[:4]:
        (tmp_path / "sub").mkdir(exist_ok=True)
        (tmp_path / "sub" / n).write_bytes((meshes / n).read_bytes())
    data = ttorch.Dataset(tmp_path, labels=[0, 1, 2, 3], resolution=32, features=("occupancy", "normal"))
    assert len(data) == 4 and data.paths == sorted(data.paths)
    # Items are the same in another process (the loader's workers), in any order.
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        items = pool.map(_getitem, [(pickle.loads(pickle.dumps(data)), n) for n in (3, 1, 0, 2)])
    items = [items[2], items[1], items[3], items[0]]
    batch, labels = ttorch.collate(items)
    assert labels == [0, 1, 2, 3]
    want = topovox.voxelize_many(data.paths, resolution=32, features=("occupancy", "normal"))
    assert np.array_equal(batch.coords, want.coords) and np.array_equal(batch.offsets, want.offsets)
    assert np.array_equal(batch.features, want.features)
    with pytest.raises(ValueError, match="labels"):
        ttorch.Dataset(tmp_path, labels=[1])


def test_torch_takes_the_arrays_without_a_copy(meshes):
    torch = pytest.importorskip("torch")
    batch = topovox.voxelize_many([meshes / "teapot.obj"], resolution=32, features=("occupancy", "normal"))
    t = torch.from_dlpack(batch.coords)
    assert t.data_ptr() == batch.coords.ctypes.data and t.dtype == torch.int32
    s = batch.torch("spconv")
    assert s["indices"].dtype == torch.int32 and s["indices"].shape == (len(batch.coords), 4)


def test_the_readme_training_loop_runs(meshes, tmp_path, monkeypatch):
    text = (REPO / "python" / "README.md").read_text()
    block = re.search(r"<!-- training-loop -->\s*```python\n(.*?)```", text, re.S)
    assert block, "python/README.md has the training-loop example"
    pytest.importorskip("torch")
    for n in NAMES[:4]:
        (tmp_path / n).write_bytes((meshes / n).read_bytes())
    monkeypatch.chdir(tmp_path)
    exec(compile(block.group(1).replace("meshes/", str(tmp_path) + "/"), "README.md", "exec"), {})


def test_the_gpu_batch_is_one_dispatch_and_equals_the_cpu(meshes):
    """method="gpu": the surface modes of the whole batch in one upload and
    one dispatch (facts["gpu"]["batch"]), each item equal to the CPU's."""
    import os

    items = rotated(meshes, 13)
    try:
        topovox.voxelize(*items[0], method="gpu", resolution=8)
    except RuntimeError as e:
        if os.environ.get("TOPOVOX_REQUIRE_GPU") == "1":
            raise
        pytest.skip(f"no GPU adapter: {e}")
    for mode, res in (("cover", 32), ("sep6", 64), ("sep26", 40)):
        batch = topovox.voxelize_many(items, mode=mode, resolution=res, method="gpu", features=("occupancy", "normal"))
        cpu = topovox.voxelize_many(items, mode=mode, resolution=res, features=("occupancy", "normal"))
        assert np.array_equal(batch.coords, cpu.coords) and np.array_equal(batch.features, cpu.features), mode
        for b in range(len(items)):
            facts = batch.item(b).facts
            assert facts["method"] == "gpu" and facts["gpu"]["batch"]["stacked"] == len(items), facts["gpu"]
            alone = topovox.voxelize(*items[b], mode=mode, resolution=res, fit="cube", method="gpu")
            assert np.array_equal(np.asarray(batch.item(b)), np.asarray(alone))


def test_progress_counts_the_meshes_voxelized(meshes, capfd):
    paths = [meshes / n for n in ("cow.obj", "fandisk.obj", "suzanne.obj", "teapot.obj")]
    seen = []
    batch = topovox.voxelize_many(paths, resolution=24, progress=lambda done, total: seen.append((done, total)))
    assert len(batch) == 4 and seen and seen[-1] == (4, 4), seen
    assert all(t == 4 for _, t in seen) and [d for d, _ in seen] == sorted({d for d, _ in seen})
    plain = topovox.voxelize_many(paths, resolution=24)
    assert np.array_equal(plain.coords, batch.coords)
    assert "meshes" not in capfd.readouterr().err
    topovox.voxelize_many(paths, resolution=24, progress=True)
    assert "topovox voxelize_many: 4/4 meshes" in capfd.readouterr().err

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        topovox.voxelize_many(paths * 50, resolution=64, progress=stop)
