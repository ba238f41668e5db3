"""PyTorch data loading: a :class:`Dataset` that voxelizes meshes in the
loader's workers and a :func:`collate` that makes one
:class:`topovox.SparseBatch` of a list of items.

Torch itself is imported only by :meth:`topovox.SparseBatch.torch` (and by
nothing at import time): the dataset and the collate function are plain
Python that ``torch.utils.data.DataLoader`` takes as they are (a map-style
dataset needs only ``__len__`` and ``__getitem__``).

>>> from torch.utils.data import DataLoader
>>> data = topovox.torch.Dataset("meshes/", resolution=32, features=("occupancy", "normal"))
>>> for batch in DataLoader(data, batch_size=8, collate_fn=topovox.torch.collate, num_workers=2):
...     t = batch.torch("torchsparse")      # coords (N, 4) [b, x, y, z], feats (N, 4)
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from .sparse import SparseBatch

__all__ = ["Dataset", "collate"]

#: Mesh file endings :class:`Dataset` collects from a folder.
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")


class Dataset:
    """Meshes (a folder, or a list of paths) voxelized on access.

    Item ``n`` is a one-item :class:`topovox.SparseBatch` of mesh ``n``
    (sorted paths), with ``label(n)`` beside it when ``labels`` is given:
    the same for a given index in any worker, in any order (voxelizing is
    deterministic). Each worker voxelizes on one thread by default
    (``threads=1``), so ``num_workers`` sets the parallelism.

    Parameters
    ----------
    meshes : path or sequence of paths
        A folder (every regular mesh file in it and below, sorted; FIFOs
        and devices are skipped) or the paths.
    labels : sequence, optional
        One label per mesh; items are then ``(batch, label)`` pairs.
    **options
        :func:`topovox.voxelize_many`'s options (``resolution``, ``mode``,
        ``features``, ``fit``, ...).
    """

    def __init__(self, meshes: Union[str, os.PathLike[str], Sequence[Union[str, os.PathLike[str]]]], labels: Optional[Sequence[Any]] = None, **options: Any) -> None:
        if isinstance(meshes, (str, os.PathLike)):
            root = os.fspath(meshes)
            if not os.path.isdir(root):
                raise NotADirectoryError(f"{root}: not a folder of meshes")
            # Regular files only, as `topovox.batch` collects: a FIFO or a
            # device named like a mesh would block the worker reading it.
            found = [
                p for d, _, fs in os.walk(root) for f in fs if f.lower().endswith(MESH_SUFFIXES) and os.path.isfile(p := os.path.join(d, f))
            ]
            self.paths: List[str] = sorted(found)
        else:
            self.paths = [os.fspath(p) for p in meshes]
        if labels is not None and len(labels) != len(self.paths):
            raise ValueError(f"{len(labels)} labels for {len(self.paths)} meshes")
        self.labels = None if labels is None else list(labels)
        self.options: Dict[str, Any] = {"threads": 1, **options}

    def __len__(self) -> int:
        return len(self.paths)

    def __getitem__(self, n: int) -> Union[SparseBatch, Tuple[SparseBatch, Any]]:
        from . import voxelize_many

        batch = voxelize_many([self.paths[n]], **self.options)
        return batch if self.labels is None else (batch, self.labels[n])


def collate(items: Sequence[Any]) -> Any:
    """One :class:`topovox.SparseBatch` of a list of dataset items (batch
    indices renumbered in order); for ``(batch, label)`` items, the batch
    and the list of labels. Use as ``DataLoader(..., collate_fn=collate)``."""
    if items and isinstance(items[0], tuple):
        return SparseBatch.concat([b for b, _ in items]), [label for _, label in items]
    return SparseBatch.concat(list(items))
