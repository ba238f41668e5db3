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
    format: Optional[str] = None,
    glob: Optional[str] = None,
    num_cpus: float = 1,
    **options: Any,
) -> List[Dict[str, Any]]:
    """Runs one Ray task per mesh still to do, as :func:`topovox.batch` would.

    Parameters
    ----------
    paths : path or iterable of paths
        Files, or folders walked for meshes.
    out_dir : path or str
        The output folder, or an fsspec URL (outputs are uploaded by each task).
    format : str, optional
        As :func:`topovox.batch` takes it (default: the run's, ``"npy"``,
        with ``run="remesh"`` ``"obj"``, with ``run="sample"`` ``"npz"``).
    glob : str, optional
        Which files of the folders to take.
    num_cpus : float
        CPUs each task asks Ray for.
    **options
        Every option :func:`topovox.voxelize` takes, or ``run="sdf"``,
        ``run="remesh"`` or ``run="sample"`` and the options of
        :func:`topovox.sdf`, :func:`topovox.remesh` or :func:`topovox.sample`,
        as :func:`topovox.batch` takes them.

    Returns
    -------
    list of dict
        The manifest records, in the order tasks finished.

    Raises
    ------
    ValueError
        Bad options.

    Examples
    --------
    >>> ray.init()
    >>> records = topovox.ray.voxelize_paths(["meshes/"], "out/", resolution=64)
    """
    import ray

    out_dir = os.fsdecode(out_dir)
    opts = _paths.options_dict(options)
    todo, _ = _paths.plan(paths, out_dir, format, glob, opts)

    @ray.remote(num_cpus=num_cpus)
    def one(inp: str, out: str) -> Dict[str, Any]:
        import json

        # Plain data back to the driver, which appends the manifest.
        record: Dict[str, Any] = json.loads(json.dumps(_paths.run_one(inp, out, format, opts)))
        return record

    pending = [one.remote(i, o) for i, o in todo]
    records = []
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        for r in ray.get(done):
            _paths.append_manifest(out_dir, [r])
            records.append(r)
    return records
