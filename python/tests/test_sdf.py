"""topovox.sdf: the same grid and values as `topovox sdf`, negative exactly
on voxelize(mode="solid")'s voxels, the band's coordinates and values,
save() in every format, and one-line errors (issue 42)."""
import json
import subprocess

import numpy as np
import pytest

import topovox


def test_same_values_as_the_command_line(tmp_path, meshes, cli):
    mesh = meshes / "cow.obj"
    field = topovox.sdf(mesh, resolution=40)
    out = tmp_path / "cli.npy"
    r = subprocess.run([str(cli), "sdf", str(mesh), "-o", str(out), "--resolution", "40", "--json"], capture_output=True, text=True, check=True)
    facts = json.loads(r.stdout)
    assert np.array_equal(np.load(out), field.to_dense())
    assert field.shape == tuple(facts["dims"]) and field.voxel_size == facts["voxel_size"]
    assert np.allclose(field.origin, facts["origin"], rtol=0, atol=0)
    assert field.signed and field.background == np.float32(facts["background"])


@pytest.mark.parametrize("sign,method", [("auto", "auto"), ("winding", "winding"), ("parity", "parity")])
def test_negative_exactly_on_the_solid(sign, method, meshes):
    mesh = meshes / "teapot.obj"
    field = topovox.sdf(mesh, resolution=32, sign=sign)
    solid = topovox.voxelize(mesh, resolution=32, mode="solid", method=method)
    assert np.array_equal(np.asarray(field) < 0, np.asarray(solid))


def test_band_coords_values_and_dense(meshes):
    field = topovox.sdf(meshes / "suzanne.obj", resolution=48, band=2.5)
    d = field.to_dense()
    assert d.dtype == np.float32 and not d.flags.writeable
    c, v = field.coords(), field.values()
    assert c.dtype == np.int32 and c.shape == (field.count, 3) and v.shape == (field.count,)
    assert np.array_equal(d[tuple(c.T)], v)
    assert (np.abs(v) < field.background).all()
    # C order, as numpy.argwhere gives.
    assert np.array_equal(c, np.argwhere(np.abs(d) < field.background))
    everything = topovox.sdf(meshes / "suzanne.obj", resolution=48, band="all")
    assert everything.count == d.size
    # The band's values are the full field's where both store.
    assert np.array_equal(np.asarray(everything)[tuple(c.T)], v)


def test_unsigned_and_arrays_in():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    f = np.array([[0, 1, 2]])
    field = topovox.sdf(v, f, voxel_size=0.1, pad=2, unsigned=True, band="all")
    d = np.asarray(field)
    assert not field.signed and (d >= 0).all()
    # The centre of voxel (i, j, k), and its distance to the triangle z = 0.
    i, j, k = 3, 3, 0
    centre = field.origin + (np.array([i, j, k]) + 0.5) * field.voxel_size
    assert abs(d[i, j, k] - abs(centre[2])) < 1e-6


@pytest.mark.parametrize("ext", ["vdb", "npy", "zarr", "vti"])
def test_save_every_format(tmp_path, ext, meshes):
    field = topovox.sdf(meshes / "cow.obj", resolution=24)
    out = tmp_path / f"cow.{ext}"
    field.save(out)
    assert out.exists()
    if ext == "npy":
        assert np.array_equal(np.load(out), field.to_dense())


def test_errors(meshes):
    with pytest.raises(ValueError, match="band"):
        topovox.sdf(meshes / "cow.obj", resolution=16, band=0)
    with pytest.raises(ValueError, match="band"):
        topovox.sdf(meshes / "cow.obj", resolution=16, band=-1)
    with pytest.raises(ValueError, match="sign"):
        topovox.sdf(meshes / "cow.obj", resolution=16, sign="odd")
    with pytest.raises(ValueError):
        topovox.sdf(np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]), np.array([[0, 1, 2]]), resolution=8)
    field = topovox.sdf(meshes / "cow.obj", resolution=16)
    with pytest.raises(ValueError, match="extension"):
        field.save("x.binvox")
