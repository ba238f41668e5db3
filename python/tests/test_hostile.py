"""Untrusted files and extreme inputs from Python (issue 65): a model names
no file outside its folder by any spelling, FIFOs and devices are refused
rather than waited on, and extreme coordinates give a Python exception,
never a panic."""

import json
import os
import struct

import numpy as np
import pytest

import topovox

TETRA = (
    np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float),
    np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
)


def gltf_naming(uri):
    """A glTF document whose one buffer (three vertices, three indices) is `uri`."""
    return json.dumps(
        {
            "asset": {"version": "2.0"},
            "buffers": [{"uri": uri, "byteLength": 42}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
            ],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "nodes": [{"mesh": 0}],
            "scenes": [{"nodes": [0]}],
            "scene": 0,
        }
    )


def triangle_buffer():
    return struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2)


@pytest.mark.parametrize(
    "spelling",
    ["file://{p}", "file:{p}", "file://localhost{p}", "FILE://{p}", "file:///{q}", "{p}", "../outside.bin", "%2E%2E/outside.bin"],
)
def test_load_mesh_reads_no_file_outside_the_folder(tmp_path, spelling):
    model = tmp_path / "model"
    model.mkdir()
    outside = tmp_path / "outside.bin"
    outside.write_bytes(triangle_buffer())
    p = str(outside)
    q = "".join(f"%{b:02X}" for b in p[1:].encode())
    (model / "m.gltf").write_text(gltf_naming(spelling.format(p=p, q=q)))
    with pytest.raises(topovox.FileFormatError, match="outside the model's folder.*--allow-external-paths"):
        topovox.load_mesh(model / "m.gltf")
    assert topovox.load_mesh(model / "m.gltf", allow_external_paths=True).faces.shape == (1, 3)


def test_every_call_taking_a_path_passes_allow_external_paths_on(tmp_path):
    model = tmp_path / "model"
    model.mkdir()
    (tmp_path / "outside.bin").write_bytes(triangle_buffer())
    (model / "m.gltf").write_text(gltf_naming("../outside.bin"))
    path = model / "m.gltf"
    calls = {
        "voxelize": lambda **kw: topovox.voxelize(path, resolution=8, **kw),
        "voxelize_many": lambda **kw: topovox.voxelize_many([path], resolution=8, **kw),
        "sdf": lambda **kw: topovox.sdf(path, resolution=8, unsigned=True, **kw),
        "sample": lambda **kw: topovox.sample(path, surface=10, **kw),
        "remesh": lambda **kw: topovox.remesh(path, resolution=8, inside="wrap", **kw),
    }
    for name, call in calls.items():
        with pytest.raises((topovox.FileFormatError, ValueError), match="outside the model's folder"):
            call()
        call(allow_external_paths=True)


@pytest.mark.parametrize("uri", ["file:///etc/passwd", "file:///proc/self/environ", "file:///dev/zero", "/etc/passwd"])
def test_system_files_are_neither_read_nor_quoted(tmp_path, uri):
    (tmp_path / "m.gltf").write_text(gltf_naming(uri))
    with pytest.raises(topovox.FileFormatError) as e:
        topovox.load_mesh(tmp_path / "m.gltf")
    assert "outside the model's folder" in str(e.value) and "refers to vertex" not in str(e.value)
    with pytest.raises(topovox.FileFormatError) as e:
        topovox.load_mesh(tmp_path / "m.gltf", allow_external_paths=True)
    said = str(e.value).split(".gltf: ", 1)[1]
    assert "refers to vertex" not in said and "root" not in said, said


def test_a_fifo_given_as_the_mesh_is_refused(tmp_path):
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="not a regular file"):
        topovox.load_mesh(fifo)


def test_dataset_skips_fifos_in_its_folder(tmp_path):
    topovox.as_mesh(*TETRA).save(tmp_path / "a.obj")
    os.mkfifo(tmp_path / "b.obj")
    data = topovox.torch.Dataset(tmp_path, resolution=8)
    assert [os.path.basename(p) for p in data.paths] == ["a.obj"]
    assert data[0].coords.shape[0] > 0


@pytest.mark.parametrize("scale", [1e308, 1e31, -1e300])
def test_meshes_past_the_range_are_a_value_error(scale):
    v, f = TETRA
    with pytest.raises(ValueError, match="range topovox computes in"):
        topovox.as_mesh(v * scale, f)


def test_every_entry_point_answers_extreme_but_valid_meshes():
    v, f = TETRA
    for scale, offset in [(1e29, 0.0), (1e-25, 0.0), (1.0, 1e15), (1.0, -3e11)]:
        mesh = topovox.as_mesh(v * scale + offset, f)
        for call in (
            lambda: topovox.voxelize(mesh, mode="solid", resolution=16),
            lambda: topovox.sdf(mesh, resolution=16),
            lambda: topovox.sample(mesh, near=100, uniform=50, seed=1),
            lambda: topovox.remesh(mesh, resolution=16),
            lambda: topovox.remesh(mesh, resolution=16, inside="wrap"),
            lambda: topovox.voxelize_many([mesh], resolution=16, mode="solid", features=("occupancy", "sdf", "normal")),
        ):
            try:
                out = call()
            except ValueError:
                continue
            if isinstance(out, topovox.Mesh):
                assert topovox.check_mesh(out)["watertight"], (scale, offset)
        q = topovox.Query(mesh)
        far = np.array([[1e308, 0, 0], [0, -1e200, 0], [np.inf, 0, 0]])
        assert np.isnan(q.distance(far)).all() and not q.contains(far).any()


def test_samples_that_would_not_be_finite_are_refused():
    mesh = topovox.as_mesh(*TETRA)
    with pytest.raises(ValueError, match="range topovox computes in"):
        topovox.sample(mesh, near=10, sigma=(1e308,))
    with pytest.raises(ValueError, match="range topovox computes in"):
        topovox.sample(mesh, near=0, uniform=10, bounds=((-1e308,) * 3, (1e308,) * 3))


BATCH_UNDER_A_LIMIT = """
import sys, numpy as np, topovox
v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
mesh = topovox.as_mesh(v, f)
kw = eval(sys.argv[1])
try:
    b = topovox.voxelize_many([mesh] * kw.pop("copies", 1), **kw)
    print("made", b.coords.shape[0])
except (ValueError, RuntimeError, MemoryError) as e:
    print("refused", str(e).splitlines()[0])
"""


@pytest.mark.parametrize(
    "kw",
    [
        'dict(resolution=2048, mode="solid", max_memory="2G")',
        'dict(resolution=1024, mode="solid", max_memory="300M", copies=4)',
        'dict(resolution=4096, features=("sdf",), max_memory="2G")',
        'dict(resolution=1024, mode="solid")',
        # The budget is the batch's, taken once: it no longer runs down to
        # "0 B" as thousands of small items hold their results.
        'dict(resolution=32, mode="solid", copies=11121)',
    ],
)
def test_voxelize_many_keeps_to_its_budget_under_an_address_space_limit(kw):
    import shutil
    import subprocess
    import sys

    if shutil.which("prlimit") is None:
        pytest.skip("prlimit is not installed")
    out = subprocess.run(
        ["prlimit", f"--as={6 << 30}", sys.executable, "-c", BATCH_UNDER_A_LIMIT, kw],
        capture_output=True,
        text=True,
        timeout=600,
    )
    # Never an abort (exit 134, "memory allocation of … failed").
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    said = out.stdout.strip()
    assert said.startswith("made") or ("refused" in said and "max_memory" in said), said
    assert "the 0 B" not in said, said
