"""Python in its ecosystem's habits: meshes from trimesh, Open3D, scenes,
paths and pairs; grids as NumPy arrays (shape, len, __array__, to_dense,
coords); grids from arrays and coordinates; pickling; trimesh voxel grids."""

import copy
import pathlib
import pickle
import subprocess
import sys

import numpy as np
import pytest

import topovox


def box(tmp_path=None):
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    f = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [2, 3, 7], [2, 7, 6], [1, 2, 6], [1, 6, 5], [0, 4, 7], [0, 7, 3]])
    return v, f


def test_numpy_habits():
    g = topovox.voxelize(*box(), resolution=10)
    assert g.shape == g.dims == (11, 11, 11) or g.shape == g.dims
    assert len(g) == g.shape[0]
    dense = np.asarray(g)
    assert dense.dtype == bool and dense.shape == g.shape and dense.sum() == g.count
    assert g.to_dense() is g.to_dense() and not g.occupancy.flags.writeable
    assert np.asarray(g, dtype=np.uint8).sum() == g.count
    c = g.coords()
    assert c.dtype == np.int32 and c.shape == (g.count, 3)
    assert (c == np.argwhere(dense)).all()


def test_grids_from_arrays_and_coordinates_round_trip_and_pickle(tmp_path):
    rng = np.random.default_rng(5)
    a = rng.random((7, 5, 6)) > 0.6
    g = topovox.VoxelGrid.from_dense(a, origin=(1.0, 2.0, 3.0), voxel_size=0.5)
    assert (g.occupancy == a).all() and (g.origin == [1.0, 2.0, 3.0]).all() and g.voxel_size == 0.5
    assert np.allclose(g.bounds, [[1.0, 2.0, 3.0], [4.5, 4.5, 6.0]])
    coords = np.argwhere(a)[::-1].copy()  # any row order
    colours = (coords * 30).astype(np.uint8)
    h = topovox.VoxelGrid.from_coords(coords, a.shape, colours=colours)
    assert (h.occupancy == a).all()
    # Attributes follow their rows into C order.
    order = np.lexsort((coords[:, 2], coords[:, 1], coords[:, 0]))
    assert (h.colours == colours[order]).all()
    for clone in (pickle.loads(pickle.dumps(h)), copy.deepcopy(h)):
        assert (clone.occupancy == a).all() and (clone.colours == h.colours).all() and clone.dims == h.dims
    with pytest.raises(ValueError, match="outside the grid"):
        topovox.VoxelGrid.from_coords([[7, 0, 0]], a.shape)
    with pytest.raises(ValueError, match="same voxel"):
        topovox.VoxelGrid.from_coords([[1, 1, 1], [1, 1, 1]], a.shape)
    h.save(tmp_path / "h.npy")
    assert (np.load(tmp_path / "h.npy") != 0).sum() == a.sum()


def test_a_voxelized_grid_pickles_with_its_attributes(meshes):
    g = topovox.voxelize(topovox.load_mesh(meshes / "spot-textured.obj"), resolution=20, attributes=True)
    h = pickle.loads(pickle.dumps(g))
    assert (h.coords() == g.coords()).all() and (h.colours == g.colours).all() and (h.normals == g.normals).all()
    assert h.facts["mode"] == "cover"


def test_meshes_from_pairs_paths_and_objects(meshes):
    v, f = box()
    want = topovox.voxelize(v, f, resolution=8).occupancy
    assert (topovox.voxelize((v, f), resolution=8).occupancy == want).all()

    class Open3DLike:  # the attributes an open3d.geometry.TriangleMesh has
        vertices, triangles = v, f

        def has_vertex_colors(self):
            return True

        vertex_colors = np.full((8, 3), 0.5)

    o3d = topovox.as_mesh(Open3DLike())
    assert (o3d.vertex_colours == 128).all()
    assert (topovox.voxelize(Open3DLike(), resolution=8).occupancy == want).all()
    g = topovox.voxelize(str(meshes / "cow.obj"), resolution=16)
    assert g.count > 0
    with pytest.raises(ValueError, match="give a topovox.Mesh"):
        topovox.as_mesh(42)


def test_python_errors_name_keywords_not_flags():
    with pytest.raises(ValueError) as e:
        topovox.voxelize(*box(), resolution=8, voxel_size=0.1)
    assert "--" not in str(e.value) and "voxel_size" in str(e.value)


trimesh = pytest.importorskip("trimesh")


def test_trimesh_meshes_scenes_colours_and_voxel_grids():
    v, f = box()
    tm = trimesh.Trimesh(v, f, process=False)
    tm.visual.face_colors = np.tile([255, 0, 0, 255], (len(f), 1))
    g = topovox.voxelize(tm, resolution=8, attributes=True)
    assert (g.colours == [255, 0, 0]).all()
    scene = trimesh.Scene([trimesh.Trimesh(v, f, process=False)])
    assert topovox.voxelize(scene, resolution=8).count == topovox.voxelize(v, f, resolution=8).count
    assert g.check(tm)["closed"] is True
    vg = g.to_trimesh()
    assert isinstance(vg, trimesh.voxel.VoxelGrid)
    centres = vg.points
    assert np.allclose(np.sort(centres, axis=0), np.sort(g.index_to_world(g.coords()), axis=0))
    assert isinstance(g.to_trimesh_mesh(), trimesh.Trimesh)


def test_a_centred_cube_as_datasets_use(meshes):
    g = topovox.voxelize(topovox.load_mesh(meshes / "cow.obj"), resolution=32, fit="cube", pad=2)
    assert g.shape == (32, 32, 32)
    occ = g.occupancy
    # The longest axis spans voxels 2..29 (cover also sets the voxels its
    # ends touch, 1 and 30); the outer pad stays empty on every side.
    assert not occ[0].any() and not occ[-1].any() and not occ[:, 0].any() and not occ[:, :, -1].any()
    assert occ[2].any() and occ[-3].any()
    # Centred: the other axes' empty margins differ by at most one voxel.
    ys = np.nonzero(occ.any(axis=(0, 2)))[0]
    assert abs(ys[0] - (31 - ys[-1])) <= 1


def test_the_typed_quick_start_runs(meshes):
    script = pathlib.Path(__file__).parents[1] / "examples" / "quickstart.py"
    r = subprocess.run([sys.executable, str(script), str(meshes / "cow.obj")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "6-separating True" in r.stdout


def test_a_textured_trimesh_keeps_its_texture(tmp_path):
    v, f = box()
    uv = np.array([[0.1, 0.1]] * 8, np.float32)  # every vertex samples the bottom-left texel
    image = np.zeros((2, 2, 3), np.uint8)
    image[1, 0] = [0, 0, 255]  # the bottom-left texel (row 1 of 2: v = 0 is the bottom)
    image[0, :] = [255, 0, 0]
    m = topovox.Mesh(v, f, uvs=uv, texture=image)
    assert m.uvs.shape == (12, 3, 2) and np.allclose(m.uvs[0, 0], [0.1, 0.9])
    g = topovox.voxelize(m, resolution=6, attributes=True)
    assert (g.colors == [0, 0, 255]).all() and g.colors is not None
    with pytest.raises(ValueError, match="come together"):
        topovox.Mesh(v, f, uvs=uv)
    PIL = pytest.importorskip("PIL.Image")
    tm = trimesh.Trimesh(v, f, process=False, visual=trimesh.visual.TextureVisuals(uv=uv, image=PIL.fromarray(image)))
    assert (topovox.voxelize(tm, resolution=6, attributes=True).colors == [0, 0, 255]).all()


def test_keywords_replace_flags_but_never_touch_file_names(tmp_path, meshes):
    import shutil

    d = tmp_path / "x--in"
    d.mkdir()
    shutil.copy(meshes / "cow.obj", d / "a--b.obj")
    with pytest.raises(ValueError) as e:
        topovox.batch([d / "a--b.obj", d / "a--b.obj"], tmp_path / "out")
    assert "a--b" in str(e.value) and "x--in" in str(e.value)
