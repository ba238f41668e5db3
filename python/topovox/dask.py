"""Voxelize many meshes on a Dask cluster: one task per mesh in a
``dask.bag``, writing the same outputs and manifest lines as
``topovox batch`` (so either can resume the other's run).

>>> from dask.distributed import Client, LocalCluster
>>> client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
>>> bag = topovox.dask.voxelize_paths(["meshes/"], "out/", format="npy", resolution=64)
>>> records = bag.compute()          # one manifest record per mesh

On a real cluster, give every worker the same view of the inputs and of
``out_dir``: a shared file system path (NFS, Lustre), or an fsspec URL for
the outputs (``s3://bucket/voxels``; each task writes locally and uploads;
the manifest is appended through fsspec, so the file system must support
appending — otherwise use a shared path for ``out_dir``).
"""

from __future__ import annotations

import os
from typing import Any, Iterable, Optional, Union

from . import _paths


def voxelize_paths(
    paths: Union[str, os.PathLike[str], Iterable[Union[str, os.PathLike[str]]]],
    out_dir: Union[str, os.PathLike[str]],
    *,
    format: Optional[str] = None,
    glob: Optional[str] = None,
    npartitions: Optional[int] = None,
    **options: Any,
) -> Any:
    """A Dask bag with one task per mesh still to do, as :func:`topovox.batch` would run.

    Meshes the manifest records as done with the same options are left out.
    Computing the bag voxelizes each mesh, writes its output and appends its
    manifest line. Each task voxelizes on one thread (``threads=`` to
    change): the cluster supplies the parallelism.

    Parameters
    ----------
    paths : path or iterable of paths
        Files, or folders walked for meshes.
    out_dir : path or str
        The output folder, or an fsspec URL.
    format : str, optional
        As :func:`topovox.batch` takes it (default: the run's, ``"npy"``,
        with ``run="remesh"`` ``"obj"``, with ``run="sample"`` ``"npz"``).
    glob : str, optional
        Which files of the folders to take.
    npartitions : int, optional
        Partitions of the bag (default: one per mesh).
    **options
        Every option :func:`topovox.voxelize` takes, or ``run="sdf"``,
        ``run="remesh"`` or ``run="sample"`` and the options of
        :func:`topovox.sdf`, :func:`topovox.remesh` or :func:`topovox.sample`,
        as :func:`topovox.batch` takes them.

    Returns
    -------
    dask.bag.Bag
        Its elements are the manifest records.

    Raises
    ------
    ValueError
        Bad options.

    Examples
    --------
    >>> records = topovox.dask.voxelize_paths(["meshes/"], "out/", resolution=64).compute()
    """
    import dask.bag as db

    out_dir = os.fsdecode(out_dir)
    opts = _paths.options_dict(options)
    todo, _ = _paths.plan(paths, out_dir, format, glob, opts)
    if not todo:
        return db.from_sequence([], npartitions=1)  # type: ignore[no-untyped-call]
    bag = db.from_sequence(todo, npartitions=npartitions or len(todo))  # type: ignore[no-untyped-call]
    return bag.map(lambda pair: _paths.process(pair[0], pair[1], out_dir, format, opts))
