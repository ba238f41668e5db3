"""Voxelize many meshes with Ray: one Ray task per mesh, writing the same
outputs and manifest lines as ``topovox batch`` (so either can resume the
other's run).

>>> import ray; ray.init(num_cpus=2)
>>> records = topovox.ray.voxelize_paths(["meshes/"], "out/", format="npy", resolution=64)

On a cluster (``ray.init(address="auto")``), every node must see the
inputs and ``out_dir`` at the same paths (a shared file system), or give
``out_dir`` as an fsspec URL (outputs are uploaded by each task). The
manifest lines are appended by the driver as tasks finish.
"""

from __future__ import annotations

import os
from typing import Any, Dict, Iterable, List, Optional, Union

from . import _paths


def voxelize_paths(
    paths: Union[str, os.PathLike[str], Iterable[Union[str, os.PathLike[str]]]],
    out_dir: Union[str, os.PathLike[str]],
    *,
    format: str = "npy",
    glob: Optional[str] = None,
    num_cpus: float = 1,
    **options: Any,
) -> List[Dict[str, Any]]:
    """Runs one Ray task per mesh still to do (``options`` as
    :func:`topovox.voxelize` takes them, plus ``colour_rule``, ``normals``,
    ``dither``); returns the manifest records, in the order tasks finished.
    Ray must be initialised (``ray.init``)."""
    import ray

    out_dir = os.fsdecode(out_dir)
    opts = _paths.options_dict(options)
    todo, _ = _paths.plan(paths, out_dir, format, glob, opts)

    @ray.remote(num_cpus=num_cpus)
    def one(inp: str, out: str) -> Dict[str, Any]:
        import json

        from topovox import _topovox

        proto, _ = _paths.split_protocol(out)
        if proto is None:
            return _topovox.process_one(inp, out, format=format, options=opts)
        import tempfile

        import fsspec  # type: ignore[import-untyped]

        with tempfile.TemporaryDirectory(prefix="topovox-") as tmp:
            local = os.path.join(tmp, os.path.basename(out))
            record = _topovox.process_one(inp, local, format=format, options=opts)
            if record.get("status") == "done":
                fs, path = fsspec.core.url_to_fs(out)
                fs.makedirs(os.path.dirname(path), exist_ok=True)
                fs.put_file(local, path)
            record["output"] = out
            out_record: Dict[str, Any] = json.loads(json.dumps(record))
            return out_record

    pending = [one.remote(i, o) for i, o in todo]
    records = []
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        for r in ray.get(done):
            _paths.append_manifest(out_dir, [r])
            records.append(r)
    return records
