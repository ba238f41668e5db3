"""One vocabulary: every option `voxelize` takes is generated from the job
crate's one list, and every front end (voxelize, batch, Dask, Ray through
the same native calls) takes each of them."""

import inspect
import json

import pytest

import topovox
from topovox import _topovox

OPTIONS = _topovox.options()
# Options that only mean something beside others.
COMPANIONS = {
    "surface": {"mode": "solid+surface"},
    "fill": {"mode": "solid"},
    "hollow": {"mode": "solid"},
    "origin": {"voxel_size": 0.25, "dims": [8, 8, 8]},
    "dims": {"voxel_size": 0.25, "origin": [-1.0, -1.0, -1.0]},
    "voxel_size": {},
}


def test_the_python_signature_is_the_list():
    params = set(inspect.signature(topovox.voxelize).parameters) - {"mesh_or_vertices", "faces", "color_rule"}
    assert params == {name for name, _, _ in OPTIONS}
    assert set(topovox.OPTIONS) == params
    assert topovox.MODES[0] == "cover" and "solid+surface" in topovox.MODES


SDF_OPTIONS = _topovox.options("sdf")


def test_the_sdf_signature_is_its_table():
    params = set(inspect.signature(topovox.sdf).parameters) - {"mesh_or_vertices", "faces"}
    assert params == {name for name, _, _ in SDF_OPTIONS}
    with pytest.raises(ValueError, match="no command"):
        _topovox.options("nope")


@pytest.mark.parametrize("name,example", [(n, e) for n, _, e in SDF_OPTIONS])
def test_every_sdf_option_is_taken_by_sdf(name, example, meshes):
    kw = dict(COMPANIONS.get(name, {}), **{name: example})
    if "voxel_size" not in kw and "resolution" not in kw:
        kw["resolution"] = 12
    field = topovox.sdf(topovox.load_mesh(meshes / "cow.obj"), **kw)
    assert field.dims[0] > 0


@pytest.mark.parametrize("name,example", [(n, e) for n, _, e in OPTIONS])
def test_every_option_is_taken_by_voxelize_and_by_batch(name, example, meshes, tmp_path):
    kw = dict(COMPANIONS.get(name, {}), **{name: example})
    if "voxel_size" not in kw and "resolution" not in kw:
        kw["resolution"] = 12
    mesh = topovox.load_mesh(meshes / "cow.obj")
    grid = topovox.voxelize(mesh, **kw)
    assert grid.count > 0
    summary = topovox.batch(meshes / "cow.obj", tmp_path / "out", **kw)
    assert (summary["done"], summary["failed"]) == (1, 0), summary
    line = json.loads((tmp_path / "out" / "manifest.jsonl").read_text().splitlines()[-1])
    assert line["status"] == "done"


def test_american_spelling_and_any_case():
    v, f = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]
    a = topovox.voxelize(v, f, resolution=8, mode="SEP6", color_rule="blend")
    b = topovox.voxelize(v, f, resolution=8, mode="sep6", colour_rule="blend")
    assert (a.occupancy == b.occupancy).all()


def test_the_typing_names_are_the_native_lists():
    from typing import get_args

    c = _topovox.choices()
    for alias, key in [
        (topovox.ModeName, "mode"),
        (topovox.MethodName, "method"),
        (topovox.FillName, "fill"),
        (topovox.GpuPathName, "gpu_path"),
        (topovox.ColourRuleName, "colour_rule"),
        (topovox.UpName, "up"),
    ]:
        assert list(get_args(alias)) == c[key], key


def _public_functions():
    import topovox.dask
    import topovox.ray

    for name in topovox.__all__:
        f = getattr(topovox, name)
        if callable(f) and not isinstance(f, type):
            yield f"topovox.{name}", f
    for cls in (topovox.VoxelGrid,):
        for name, f in vars(cls).items():
            if not name.startswith("_") and callable(f) or isinstance(f, staticmethod):
                yield f"{cls.__name__}.{name}", getattr(cls, name)
    yield "topovox.dask.voxelize_paths", topovox.dask.voxelize_paths
    yield "topovox.ray.voxelize_paths", topovox.ray.voxelize_paths


@pytest.mark.parametrize("name,f", list(_public_functions()))
def test_every_public_function_has_a_numpy_style_docstring(name, f):
    doc = f.__doc__ or ""
    for section in ("Returns\n", "Examples\n"):
        if section == "Returns\n" and name.endswith(".save"):
            continue
        assert section in doc, f"{name}: no {section.strip()} section"
    assert "Parameters\n" in doc or "()" in doc.splitlines()[0] or name.endswith(("coords", "indices", "to_dense", "greedy_mesh", "to_trimesh", "to_trimesh_mesh")), name


def test_batch_runs_sdf_with_its_options_and_refuses_the_others(meshes, tmp_path):
    # Issue 53.7: `batch` refused `band`.
    s = topovox.batch(meshes / "cow.obj", tmp_path / "f", run="sdf", band=2, resolution=12, format="vdb")
    assert (s["done"], s["failed"]) == (1, 0), s
    line = json.loads((tmp_path / "f" / "manifest.jsonl").read_text().splitlines()[-1])
    assert line["options"]["run"] == "sdf" and line["options"]["band"] == 2
    one = topovox.sdf(topovox.load_mesh(meshes / "cow.obj"), band=2, resolution=12)
    one.save(tmp_path / "one.vdb")
    assert (tmp_path / "f" / "cow.vdb").read_bytes() == (tmp_path / "one.vdb").read_bytes()
    with pytest.raises(ValueError, match='unknown option "band"'):
        topovox.batch(meshes / "cow.obj", tmp_path / "g", band=2)
    with pytest.raises(ValueError, match='unknown option "mode"'):
        topovox.batch(meshes / "cow.obj", tmp_path / "h", run="sdf", mode="solid")
    with pytest.raises(ValueError, match="run"):
        topovox.batch(meshes / "cow.obj", tmp_path / "i", run="render")


def test_options_lists_every_commands_options_with_help_and_example():
    assert set(topovox.options()) == set(topovox.OPTIONS)
    assert all(help == topovox.OPTIONS[name] for name, (help, _) in topovox.options().items())
    for command, name in [("sdf", "band"), ("remesh", "inside"), ("sample", "near"), ("batch", "resolution")]:
        help, example = topovox.options(command)[name]
        assert help and example is not None, (command, name)
    with pytest.raises(ValueError, match="no command"):
        topovox.options("paint")
