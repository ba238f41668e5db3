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
    assert topovox.load_mesh(model / "m.gltf", allow_external_paths=True).triangles.shape == (1, 3)


@pytest.mark.parametrize("uri", ["file:///etc/passwd", "file:///proc/self/environ", "file:///dev/zero", "/etc/passwd"])
def test_system_files_are_neither_read_nor_quoted(tmp_path, uri):
    (tmp_path / "m.gltf").write_text(gltf_naming(uri))
    with pytest.raises(topovox.FileFormatError) as e:
        topovox.load_mesh(tmp_path / "m.gltf")
    assert "outside the model's folder" in str(e.value) and "refers to vertex" not in str(e.value)
    with pytest.raises(topovox.FileFormatError) as e:
        topovox.load_mesh(tmp_path / "m.gltf", allow_external_paths=True)
    assert "refers to vertex" not in str(e.value) and "root" not in str(e.value)


def test_a_fifo_given_as_the_mesh_is_refused(tmp_path):
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="not a regular file"):
        topovox.load_mesh(fifo)
