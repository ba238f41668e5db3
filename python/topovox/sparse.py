"""Sparse training batches: :class:`SparseBatch`, what
:func:`topovox.voxelize_many` returns, and its layouts for the
sparse-convolution libraries.

A batch holds plain contiguous NumPy arrays:

- ``coords``: ``(N, 4)`` int32, ``[b, i, j, k]``, sorted by batch index and
  then in C order (``i``, then ``j``, then ``k``), each item's rows
  contiguous;
- ``features``: ``(N, C)`` float32, the columns ``columns`` names, in the
  order asked;
- ``offsets``: ``(B + 1,)`` int64, item ``b``'s rows are
  ``offsets[b]:offsets[b + 1]``;
- ``origins``, ``voxel_sizes`` ``(B, 3)`` float64 and ``dims`` ``(B, 3)``
  int64: each item's grid, to map indices back to world coordinates
  (voxel ``(i, j, k)`` spans ``origin + (i, j, k) * size`` to
  ``origin + (i + 1, j + 1, k + 1) * size``).

Being NumPy arrays that own their memory, ``torch.from_numpy`` and
``torch.from_dlpack`` take them without a copy.
"""

from __future__ import annotations

import importlib
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

#: The layouts :meth:`SparseBatch.layout` gives, with the documentation
#: each follows.
LAYOUTS: Dict[str, str] = {
    "spconv": "spconv 2.x SparseConvTensor(features, indices, spatial_shape, batch_size): "
    "indices int32 (N, 4) [batch, z, y, x] (batch first, then the axes of spatial_shape = (nz, ny, nx))",
    "torchsparse": "TorchSparse >= 2.1 SparseTensor(feats, coords): coords int32 (N, 4) [batch, x, y, z] "
    "(batch first since 2.1.0; earlier versions put it last)",
    "minkowski": "MinkowskiEngine 0.5 SparseTensor(features, coordinates): coordinates int32 (N, 4) "
    "[batch, x, y, z] (batch first since 0.4)",
    "fvdb": "fVDB gridbatch_from_ijk(JaggedTensor ijk, voxel_sizes, origins), as openvdb.org/documentation/fvdb "
    "documents it (read 2026-11): ijk int32 (N, 3) per item (joffsets int64 (B + 1)), origins the world centre "
    "of voxel (0, 0, 0)",
    "ocnn": "ocnn-pytorch Points(points, features=..., batch_size) then Octree(depth).build_octree, as "
    "ocnn/octree/points.py of github.com/octree-nn/ocnn-pytorch documents it (read 2026-11): points float32 "
    "(N, 3) in [-1, 1], batch_id float32 (N, 1) as its merge_points makes it",
}


class SparseBatch:
    """Voxels of many meshes as one sparse tensor (see the module doc).

    Built by :func:`topovox.voxelize_many` or :meth:`concat`; items that
    failed with ``on_error="skip"`` are empty and listed in ``errors``.
    """

    def __init__(
        self,
        coords: np.ndarray,
        features: np.ndarray,
        offsets: np.ndarray,
        grids: Sequence[Any],
        columns: Sequence[str],
        errors: Optional[Dict[int, str]] = None,
    ) -> None:
        self.coords = np.ascontiguousarray(coords, dtype=np.int32)
        self.features = np.ascontiguousarray(features, dtype=np.float32)
        self.offsets = np.ascontiguousarray(offsets, dtype=np.int64)
        self.grids: List[Any] = list(grids)
        self.columns: Tuple[str, ...] = tuple(columns)
        self.errors: Dict[int, str] = dict(errors or {})
        b = len(self.grids)
        if self.offsets.shape != (b + 1,) or self.coords.shape != (int(self.offsets[-1]), 4) or self.features.shape != (len(self.coords), len(self.columns)):
            raise ValueError(f"inconsistent batch: {b} items, offsets {self.offsets.shape}, coords {self.coords.shape}, features {self.features.shape}")
        nan3 = np.full(3, np.nan)
        self.origins = np.array([g.origin if g is not None else nan3 for g in self.grids], dtype=np.float64).reshape(b, 3)
        self.voxel_sizes = np.array([g.spacing if g is not None else nan3 for g in self.grids], dtype=np.float64).reshape(b, 3)
        self.dims = np.array([g.dims if g is not None else (0, 0, 0) for g in self.grids], dtype=np.int64).reshape(b, 3)

    @property
    def batch_size(self) -> int:
        """Items in the batch (failed ones included)."""
        return len(self.grids)

    def __len__(self) -> int:
        return len(self.grids)

    def __repr__(self) -> str:
        return f"SparseBatch({self.batch_size} items, {len(self.coords)} voxels, columns={list(self.columns)})"

    def item(self, b: int) -> Any:
        """Item ``b`` as the :class:`topovox.VoxelGrid` ``voxelize`` gives for that mesh alone.

        Raises
        ------
        ValueError
            The item failed (``on_error="skip"``): the message says why.
        """
        g = self.grids[b]
        if g is None:
            raise ValueError(self.errors.get(b % len(self.grids), f"item {b} has no grid"))
        return g

    def rows(self, b: int) -> Tuple[np.ndarray, np.ndarray]:
        """Item ``b``'s ``(n, 3)`` int32 indices ``[i, j, k]`` and ``(n, C)`` features (views)."""
        lo, hi = int(self.offsets[b]), int(self.offsets[b + 1])
        return self.coords[lo:hi, 1:], self.features[lo:hi]

    def to_dense(self, features: bool = False) -> np.ndarray:
        """A dense array: occupancy ``(B, X, Y, Z)`` bool, or with
        ``features=True`` the features ``(B, C, X, Y, Z)`` float32 (zero where
        no voxel is set). ``X, Y, Z`` are the largest dims of any item (all
        equal with ``fit="cube"``); items start at index 0."""
        shape = tuple(int(v) for v in self.dims.max(axis=0)) if len(self) else (0, 0, 0)
        b, i, j, k = self.coords.T
        if not features:
            out = np.zeros((len(self),) + shape, dtype=bool)
            out[b, i, j, k] = True
            return out
        dense = np.zeros((len(self), len(self.columns)) + shape, dtype=np.float32)
        dense[b, :, i, j, k] = self.features
        return dense

    def layout(self, library: str) -> Dict[str, Any]:
        """The batch in a sparse-convolution library's documented layout.

        Parameters
        ----------
        library : {"spconv", "torchsparse", "minkowski", "fvdb", "ocnn"}
            See :data:`LAYOUTS` for the order, dtype and documentation
            followed.

        Returns
        -------
        dict
            NumPy arrays named as the library's constructor names them
            (``indices``/``spatial_shape`` for spconv, ``coords``/``feats``
            for TorchSparse, ``coordinates``/``features`` for
            MinkowskiEngine, ``ijk``/``joffsets``/``voxel_sizes``/``origins``
            for fVDB, ``points``/``batch_id``/``depth`` for O-CNN), plus
            ``batch_size`` and ``order``.

        Examples
        --------
        >>> t = batch.layout("spconv")
        >>> x = spconv.SparseConvTensor(torch.from_numpy(t["features"]), torch.from_numpy(t["indices"]), t["spatial_shape"], t["batch_size"])
        """
        name = library.lower()
        b = self.coords[:, :1]
        ijk = self.coords[:, 1:]
        common: Dict[str, Any] = {"batch_size": len(self)}
        if name == "spconv":
            shape = [int(v) for v in self.dims.max(axis=0)[::-1]] if len(self) else [0, 0, 0]
            return {**common, "indices": np.ascontiguousarray(np.hstack([b, ijk[:, ::-1]])), "features": self.features, "spatial_shape": shape, "order": "b,z,y,x"}
        if name in ("torchsparse", "minkowski"):
            keys = ("coords", "feats") if name == "torchsparse" else ("coordinates", "features")
            return {**common, keys[0]: self.coords, keys[1]: self.features, "order": "b,x,y,z"}
        if name == "fvdb":
            centres = self.origins + 0.5 * self.voxel_sizes
            return {**common, "ijk": np.ascontiguousarray(ijk), "joffsets": self.offsets, "features": self.features, "voxel_sizes": self.voxel_sizes, "origins": centres, "order": "x,y,z"}
        if name == "ocnn":
            side = int(self.dims.max()) if len(self.coords) else 1
            depth = max(1, (side - 1).bit_length())
            points = ((ijk.astype(np.float32) + 0.5) * np.float32(2.0 / (1 << depth)) - np.float32(1.0)).astype(np.float32)
            return {**common, "points": np.ascontiguousarray(points), "batch_id": b.astype(np.float32), "features": self.features, "depth": depth, "order": "x,y,z"}
        raise ValueError(f"unknown layout {library!r} (expected one of: {', '.join(LAYOUTS)})")

    def torch(self, layout: str = "torchsparse") -> Dict[str, Any]:
        """:meth:`layout` with every array a ``torch.Tensor`` sharing its
        memory (``torch.from_numpy``; no copy). Imports torch."""
        torch = importlib.import_module("torch")
        return {k: torch.from_numpy(v) if isinstance(v, np.ndarray) else v for k, v in self.layout(layout).items()}

    @classmethod
    def concat(cls, batches: Sequence["SparseBatch"]) -> "SparseBatch":
        """One batch of the items of ``batches``, in order (a data loader's
        collate); their columns must agree."""
        if not batches:
            raise ValueError("concat of no batches")
        columns = batches[0].columns
        for x in batches:
            if x.columns != columns:
                raise ValueError(f"batches with different feature columns: {list(columns)} and {list(x.columns)}")
        starts = np.cumsum([0] + [len(x) for x in batches])
        coords = np.concatenate([x.coords + np.array([s, 0, 0, 0], dtype=np.int32) for x, s in zip(batches, starts)])
        rows = np.cumsum([0] + [len(x.coords) for x in batches])
        offsets = np.concatenate([[0]] + [x.offsets[1:] + r for x, r in zip(batches, rows)])
        errors = {int(s) + b: m for x, s in zip(batches, starts) for b, m in x.errors.items()}
        grids = [g for x in batches for g in x.grids]
        return cls(coords, np.concatenate([x.features for x in batches]), offsets, grids, columns, errors)
