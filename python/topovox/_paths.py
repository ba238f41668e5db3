"""Shared by the Dask and Ray helpers: the batch plan (the same as
``topovox batch``), one mesh's task, and manifest lines, so a run started by
one engine can be resumed by another (or by ``topovox batch``)."""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any, Dict, Iterable, List, Optional, Tuple, Union

from . import _topovox

PathLike = Union[str, os.PathLike[str]]


def split_protocol(path: str) -> Tuple[Optional[str], str]:
    """``("s3", "bucket/key")`` for ``s3://bucket/key``; ``(None, path)``
    for a plain path (``file://`` counts as plain)."""
    if "://" in path:
        proto, rest = path.split("://", 1)
        if proto == "file":
            return None, rest
        return proto, rest
    return None, path


def options_dict(options: Dict[str, Any]) -> Dict[str, Any]:
    from . import _options

    return _options(options)


def plan(
    paths: Union[PathLike, Iterable[PathLike]], out_dir: str, format: Optional[str], glob: Optional[str], options: Dict[str, Any]
) -> Tuple[List[Tuple[str, str]], Any]:
    """The meshes still to do as ``(input, output)`` pairs, and the options'
    fingerprint. For an fsspec URL ``out_dir`` the outputs are named under
    it; the plan (and what is done) is read from a local mirror of its
    manifest."""
    if isinstance(paths, (str, bytes, os.PathLike)):
        paths = [paths]
    proto, rest = split_protocol(out_dir)
    local_out = rest if proto is None else _remote_manifest_mirror(out_dir)
    listed, fingerprint = _topovox.batch_plan([os.fsdecode(p) for p in paths], local_out, format=format, glob=glob, options=options)
    todo = []
    for inp, out, done in listed:
        if done:
            continue
        if proto is not None:
            out = f"{proto}://{rest.rstrip('/')}/{os.path.relpath(out, local_out)}"
        todo.append((inp, out))
    return todo, fingerprint


def _remote_manifest_mirror(out_dir: str) -> str:
    """A local folder holding a copy of the remote manifest (and nothing
    else), so the native planner can tell what is done."""
    import fsspec  # type: ignore[import-untyped]

    local = tempfile.mkdtemp(prefix="topovox-manifest-")
    fs, root = fsspec.core.url_to_fs(out_dir)
    remote_manifest = root.rstrip("/") + "/manifest.jsonl"
    if fs.exists(remote_manifest):
        with fs.open(remote_manifest, "rb") as src, open(os.path.join(local, "manifest.jsonl"), "wb") as dst:
            dst.write(src.read())
    return local


def run_one(inp: str, out: str, format: Optional[str], options: Dict[str, Any]) -> Dict[str, Any]:
    """One mesh: voxelize ``inp`` and write ``out`` (written locally and
    uploaded through fsspec when ``out`` is a URL); returns its manifest
    record, without appending it."""
    proto, _ = split_protocol(out)
    if proto is None:
        return _topovox.process_one(split_protocol(inp)[1], split_protocol(out)[1], format=format, options=options)
    import fsspec

    with tempfile.TemporaryDirectory(prefix="topovox-") as tmp:
        local = os.path.join(tmp, os.path.basename(out))
        record = _topovox.process_one(inp, local, format=format, options=options)
        if record.get("status") == "done":
            fs, path = fsspec.core.url_to_fs(out)
            fs.makedirs(os.path.dirname(path), exist_ok=True)
            fs.put_file(local, path)
        record["output"] = out
    return record


def process(inp: str, out: str, out_dir: str, format: Optional[str], options: Dict[str, Any]) -> Dict[str, Any]:
    """One mesh as :func:`run_one` does it, its manifest line appended."""
    record = run_one(inp, out, format, options)
    append_manifest(out_dir, [record])
    return record


def append_manifest(out_dir: str, records: List[Dict[str, Any]]) -> None:
    """Appends records to ``out_dir/manifest.jsonl``, one line each (one
    write per line; through fsspec for URLs, where the file system must
    support appending)."""
    proto, rest = split_protocol(out_dir)
    if proto is None:
        _topovox.append_manifest(rest, [json.dumps(r) for r in records])
        return
    import fsspec

    fs, root = fsspec.core.url_to_fs(out_dir)
    fs.makedirs(root, exist_ok=True)
    with fs.open(root.rstrip("/") + "/manifest.jsonl", "ab") as f:
        for r in records:
            f.write((json.dumps(r) + "\n").encode())
