"""voxel_size=(sx, sy, sz): a size per axis everywhere a voxel size is
taken, the grid reporting it, the same voxels as the command line, the
metamorphic law (sizes s ≡ the mesh scaled by 1/s on unit cubes), world
normals, coverage relative to the face a piece is parallel to, files that
keep the spacing, and refusals by the formats that only know cubes
(issue 43)."""
import json
import subprocess

import numpy as np
import pytest

import topovox

SIZES = (0.05, 0.05, 0.18)


def test_same_voxels_as_the_command_line(tmp_path, meshes, cli):
    mesh = meshes / "cow.obj"
    grid = topovox.voxelize(mesh, voxel_size=SIZES, mode="sep6")
    out = tmp_path / "cli.npy"
    r = subprocess.run(
        [str(cli), "voxelize", str(mesh), "-o", str(out), "--voxel-size", "0.05,0.05,0.18", "--mode", "sep6", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    facts = json.loads(r.stdout)
    assert facts["voxel_size"] == list(SIZES)
    assert np.array_equal(np.load(out), grid.to_dense())
    assert grid.voxel_size == SIZES and np.array_equal(grid.spacing, SIZES)
    assert np.allclose(grid.bounds[1] - grid.bounds[0], np.array(grid.shape) * SIZES)
    # Cubes keep the scalar.
    cubes = topovox.voxelize(mesh, voxel_size=0.1)
    assert cubes.voxel_size == 0.1 and np.array_equal(cubes.spacing, [0.1] * 3)


@pytest.mark.parametrize("mode", ["cover", "sep26", "sep6", "tunnel26", "solid"])
def test_sizes_equal_the_mesh_scaled_onto_unit_cubes(mode, meshes):
    # The solid of a closed mesh (its integer winding number) is kept by
    # stretching; the generalized winding number of an open mesh is measured
    # in the world's shape (solid angles are not kept: see the next test).
    mesh = topovox.load_mesh(meshes / ("cow.obj" if mode == "solid" else "suzanne.obj"))
    s = np.array([0.031, 0.07, 0.0213])
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    origin = lo - 2 * s
    dims = tuple(int(d) for d in np.ceil((hi - lo) / s) + 4)
    a = topovox.voxelize(mesh, mode=mode, origin=tuple(origin), voxel_size=tuple(s), dims=dims)
    scaled = topovox.Mesh(mesh.vertices / s, mesh.faces)
    b = topovox.voxelize(scaled, mode=mode, origin=tuple(origin / s), voxel_size=1.0, dims=dims)
    assert a.count > 100 and np.array_equal(a.to_dense(), b.to_dense())


def test_open_solids_on_boxes_follow_the_world_winding_number(meshes):
    mesh = topovox.load_mesh(meshes / "suzanne.obj")
    g = topovox.voxelize(mesh, mode="solid", voxel_size=(0.031, 0.07, 0.0213))
    centres = g.index_to_world(np.indices(g.shape).reshape(3, -1).T)
    w = topovox.Query(mesh).winding_number(centres)
    assert g.count > 100 and np.array_equal(np.abs(w) >= 0.5, g.to_dense().reshape(-1))


def test_normals_are_world_unit_normals_and_coverage_is_per_face():
    # A tilted plane: its world normal, whatever the voxel shape.
    n = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    u = np.cross(n, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    c = np.array([1.0, 1.0, 1.0])
    v = np.array([c - 3 * u - 3 * w, c + 3 * u - 3 * w, c + 3 * u + 3 * w, c - 3 * u + 3 * w])
    g = topovox.voxelize(v, [[0, 1, 2], [0, 2, 3]], origin=(0, 0, 0), voxel_size=(0.1, 0.3, 0.05), dims=(20, 7, 40), normals=True)
    normals = g.normals
    assert normals is not None and len(normals) == g.count > 0
    assert np.allclose(np.abs(normals @ n), 1.0, atol=1e-5)
    # A plane parallel to the xy face covers each voxel it spans fully: 1.
    flat = np.array([[0, 0, 0.3], [4, 0, 0.3], [4, 2, 0.3], [0, 2, 0.3]], float)
    g = topovox.voxelize(flat, [[0, 1, 2], [0, 2, 3]], origin=(0, 0, 0), voxel_size=(0.5, 0.25, 2.0), dims=(8, 8, 1), attributes=True)
    assert g.count == 64
    assert np.allclose(g.coverage, 1.0, atol=1e-6)


@pytest.mark.parametrize("ext", ["vti", "vdb", "zarr", "npz", "ply", "txt"])
def test_files_keep_the_spacing(ext, tmp_path, meshes):
    grid = topovox.voxelize(meshes / "cow.obj", voxel_size=SIZES)
    path = tmp_path / f"cow.{ext}"
    grid.save(path)
    back = topovox.load_voxels(path)
    assert back.voxel_size == pytest.approx(SIZES, rel=1e-6) if ext == "ply" else back.voxel_size == SIZES
    assert np.array_equal(back.to_dense(), grid.to_dense())
    assert np.allclose(back.origin, grid.origin)


@pytest.mark.parametrize("ext", ["binvox", "vox", "schem"])
def test_cubes_only_formats_refuse_and_write_nothing(ext, tmp_path, meshes):
    grid = topovox.voxelize(meshes / "cow.obj", voxel_size=SIZES)
    path = tmp_path / f"cow.{ext}"
    with pytest.raises(ValueError, match=r"cubic voxels only.*\.vti"):
        grid.save(path)
    assert not path.exists()


def test_from_coords_dense_pickle_and_distance_fields(meshes):
    g = topovox.VoxelGrid.from_dense(np.ones((2, 3, 4), bool), origin=(1, 2, 3), voxel_size=[0.5, 1, 2])
    assert g.voxel_size == (0.5, 1.0, 2.0)
    assert np.array_equal(g.bounds, [[1, 2, 3], [2, 5, 11]])
    import pickle

    assert pickle.loads(pickle.dumps(g)).voxel_size == (0.5, 1.0, 2.0)
    with pytest.raises(ValueError, match="three"):
        topovox.VoxelGrid.from_dense(np.ones((2, 2, 2), bool), voxel_size=(1, 2))
    with pytest.raises(ValueError, match="3 values"):
        topovox.voxelize(meshes / "cow.obj", voxel_size=(0.1, 0.2))
    field = topovox.sdf(meshes / "teapot.obj", voxel_size=(0.2, 0.1, 0.3), band=2)
    solid = topovox.voxelize(meshes / "teapot.obj", voxel_size=(0.2, 0.1, 0.3), mode="solid")
    assert field.voxel_size == (0.2, 0.1, 0.3) and field.background == pytest.approx(0.6)
    assert np.array_equal(np.asarray(field) < 0, np.asarray(solid))
