"""topovox: triangle meshes (and polylines) to voxel grids with a stated,
tested topological guarantee, fast, as NumPy arrays.

The voxels are exactly those the ``topovox`` command line writes for the same
options (both run the same Rust code), bit for bit.

>>> import topovox
>>> mesh = topovox.load_mesh("bunny.obj")
>>> grid = topovox.voxelize(mesh, mode="sep6", resolution=128)
>>> grid.occupancy.shape        # (nx, ny, nz), element [i, j, k]
>>> grid.save("bunny.binvox")

Modes (``mode=``):

- ``cover``: every voxel whose closed box meets a triangle (26-separating).
- ``sep26``: Laine's space-diagonal target (26-separating, subset of cover).
- ``sep6``: Laine's 3D crosshair (6-separating, thin).
- ``ss6``: Schwarz-Seidel's 6-separating test.
- ``tunnel18``, ``tunnel26``: 18- and 26-tunnel-free (Laine's targets from
  the centre to face centres and edge midpoints, and corners).
- ``bubble``: randomized 6-separating targets (``seed=``).
- ``diagonal``: one alternating body diagonal per voxel (6-separating).
- ``line26``, ``line6``: polylines, 26- or 6-connected.
- ``pos``: the published projected optimal scanline algorithm (no guarantee).
- ``solid``: voxels whose centre is inside (the winding number of the mesh
  oriented by parts and nesting: flipped faces do not matter, overlapping
  shells give their union, nested ones cavities); ``solid+surface``: united with a surface mode
  (``surface=``); ``fill="flood"`` and ``hollow=6|26`` as in the CLI.

Grids: ``resolution=N`` (the longest side of the bounding box spans N
voxels; the default is 128), ``voxel_size=S`` (fitted to the bounding box),
or ``origin=(x, y, z), voxel_size=S, dims=(nx, ny, nz)`` exactly; ``pad=P``
adds empty voxels around a fitted grid. ``voxel_size=(sx, sy, sz)`` gives a
size per axis (boxes: a scan's spacing, a layer height). Voxel ``(i, j, k)``
is the closed box ``[origin + (i, j, k) * s, origin + (i + 1, j + 1, k + 1) * s]``
(per axis); every mode's rules hold in index space, where voxels are cubes.

Errors: ``ValueError`` for bad arguments and bad arrays, ``OSError``
subclasses for files (``FileNotFoundError``, ``PermissionError``,
:class:`FileFormatError` for malformed content), ``RuntimeError`` for
failures while running (no GPU, not enough memory). The messages are the
command line's.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Iterable, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np

from . import _topovox
from ._topovox import DistanceGrid, FileFormatError, Mesh, VoxelGrid, load_mesh, load_voxels
from .sparse import SparseBatch

__version__ = _topovox.__version__

__all__ = [
    "Mesh",
    "VoxelGrid",
    "DistanceGrid",
    "FileFormatError",
    "load_mesh",
    "load_voxels",
    "as_mesh",
    "voxelize",
    "voxelize_many",
    "SparseBatch",
    "FEATURES",
    "sdf",
    "Query",
    "distance",
    "contains",
    "closest",
    "winding_number",
    "sample",
    "remesh",
    "check_mesh",
    "batch",
    "MODES",
    "METHODS",
    "FORMATS",
    "OPTIONS",
    "options",
]

# The names come from the one list the command line uses too.
_CHOICES = _topovox.choices()
#: Every mode, as ``voxelize(mode=...)`` takes it.
MODES = tuple(_CHOICES["mode"])
#: Every method, as ``voxelize(method=...)`` takes it.
METHODS = tuple(_CHOICES["method"])
#: Every output format ``VoxelGrid.save`` and ``batch`` write.
FORMATS = tuple(_CHOICES["format"])
#: The option names as types checkers see them (names are also taken in
#: any case at run time); the tests check each against the native list.
ModeName = Literal["cover", "sep26", "sep6", "ss6", "tunnel18", "tunnel26", "bubble", "diagonal", "solid", "solid+surface", "line6", "line26", "pos"]
MethodName = Literal["auto", "reference", "fast", "scanline", "gpu", "parity", "winding"]
FillName = Literal["flood"]
GpuPathName = Literal["compute", "raster", "msaa-approx"]
ColourRuleName = Literal["dominant", "blend"]
UpName = Literal["x", "y", "z"]
FitName = Literal["box", "cube"]
SignName = Literal["auto", "parity", "winding"]
InsideName = Literal["auto", "parity", "winding", "wrap"]
SurfaceKindName = Literal["smooth", "blocky"]
#: A voxel size: one edge (cubes) or ``(sx, sy, sz)``.
VoxelSizeLike = Union[float, Tuple[float, float, float]]
#: The per-voxel features :func:`voxelize_many` measures, with their help.
FEATURES = {name: help for name, help in _topovox.features()}
FeatureName = Literal["occupancy", "normal", "colour", "color", "coverage", "material", "sdf"]
#: Every option :func:`voxelize` and :func:`batch` take, with its help.
OPTIONS = {name: help for name, help, _example in _topovox.options()}

CommandName = Literal["voxelize", "batch", "sdf", "remesh", "sample"]


def options(command: CommandName = "voxelize") -> Dict[str, Tuple[str, Any]]:
    """Every option a command takes, with its help and an example value.

    The same rows as the CLI's flags (``resolution`` is ``--resolution``);
    ``OPTIONS`` is ``options()`` without the examples.

    Parameters
    ----------
    command : {"voxelize", "batch", "sdf", "remesh", "sample"}
        Whose options: :func:`voxelize` and :func:`batch` (the default),
        :func:`sdf`, :func:`remesh` or :func:`sample`.

    Returns
    -------
    dict
        ``{name: (help, example)}``, in the table's order.

    Raises
    ------
    ValueError
        For another command.

    Examples
    --------
    >>> help, example = topovox.options("sdf")["band"]
    """
    return {name: (help, example) for name, help, example in _topovox.options(command)}

MeshLike = Union[Mesh, Any]

#: The submodules ``import topovox`` makes reachable on first use, without
#: importing Dask or Ray before then.
_LAZY = ("dask", "ray", "torch")


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _as_float_points(a: Any, name: str) -> np.ndarray:
    """float64/float32 arrays pass through untouched (the native side copies
    them once, strided or not); anything else is converted."""
    if isinstance(a, np.ndarray) and a.dtype in (np.float64, np.float32):
        return a
    try:
        return np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must be an (n, 3) array of numbers: {e}") from None


def _as_index_array(a: Any, name: str) -> np.ndarray:
    if isinstance(a, np.ndarray) and a.dtype in (np.int64, np.int32, np.uint32, np.uint64):
        return a
    arr = np.asarray(a)
    if arr.dtype.kind == "f":
        if not np.all(np.isfinite(arr)) or not np.all(arr == np.floor(arr)):
            raise ValueError(f"{name} must hold integer vertex indices; got non-integer values")
    elif arr.dtype.kind not in "iub":
        raise ValueError(f"{name} must be an integer array; got dtype {arr.dtype}")
    return arr.astype(np.int64)


def _colours(c: Any) -> Optional[np.ndarray]:
    """(n, 3) uint8 sRGB from uint8 or float (0..1) colours, RGB or RGBA."""
    if c is None:
        return None
    arr = np.asarray(c)
    if arr.ndim != 2 or arr.shape[1] < 3:
        raise ValueError(f"colours must have shape (n, 3) or (n, 4); got {arr.shape}")
    arr = arr[:, :3]
    if arr.dtype.kind == "f":
        return np.clip(np.round(arr * 255.0), 0, 255).astype(np.uint8)
    return arr.astype(np.uint8)


def _trimesh_appearance(mesh: Any) -> Dict[str, Any]:
    """A trimesh mesh's colours as :class:`Mesh` keywords: its texture and
    per-vertex UVs as they are, or its vertex or face colours."""
    visual: Any = getattr(mesh, "visual", None)
    kind = getattr(visual, "kind", None)
    if visual is None:
        return {}
    if kind == "texture":
        material = getattr(visual, "material", None)
        image = getattr(material, "baseColorTexture", None) or getattr(material, "image", None)
        uv = getattr(visual, "uv", None)
        if image is not None and uv is not None:
            rgba = np.asarray(image.convert("RGBA") if hasattr(image, "convert") else image)
            return {"uvs": np.asarray(uv, dtype=np.float32), "texture": rgba}
        try:  # a texture without an image: the colours trimesh samples
            visual = visual.to_color()
            kind = visual.kind
        except Exception:
            return {}
    if kind == "vertex":
        return {"vertex_colours": _colours(visual.vertex_colors)}
    if kind == "face":
        return {"face_colours": _colours(visual.face_colors)}
    return {}


def _tensor_array(t: Any) -> np.ndarray:
    """An Open3D tensor (on any device) as a NumPy array."""
    return np.asarray(t.cpu().numpy() if hasattr(t, "cpu") else t.numpy())


def _from_open3d_tensor(m: Any) -> Mesh:
    """An ``open3d.t.geometry.TriangleMesh``: ``vertex.positions``,
    ``triangle.indices`` and, when present, ``vertex.colors``."""
    v, t = m.vertex, m.triangle
    if "positions" not in v or "indices" not in t:
        raise ValueError("an Open3D tensor TriangleMesh needs vertex.positions and triangle.indices")
    vc = _colours(_tensor_array(v["colors"])) if "colors" in v else None
    positions = _as_float_points(_tensor_array(v["positions"]), "vertices")
    return Mesh(positions, _as_index_array(_tensor_array(t["indices"]), "triangles"), vertex_colours=vc)


def as_mesh(
    mesh_or_vertices: Union[MeshLike, np.ndarray, str, os.PathLike[str]],
    faces: Optional[Any] = None,
    max_memory: Optional[Union[int, str]] = None,
    allow_external_paths: bool = False,
) -> Mesh:
    """A :class:`Mesh` from whatever holds a triangle mesh.

    Parameters
    ----------
    mesh_or_vertices
        A :class:`Mesh`; a path (read by :func:`load_mesh`); a
        ``trimesh.Trimesh`` (``vertices`` and ``faces``, with its texture and
        UVs, or its vertex or face colours) or ``trimesh.Scene``
        (its geometry, concatenated); an Open3D ``TriangleMesh``
        (``vertices`` and ``triangles``, with its vertex colours) or
        tensor-API ``open3d.t.geometry.TriangleMesh`` (``vertex.positions``,
        ``triangle.indices``, ``vertex.colors``); a
        ``(vertices, faces)`` pair; or an ``(n, 3)`` vertex array with
        ``faces``.
    faces
        ``(m, 3)`` integer vertex indices, when vertices are given.
    max_memory, allow_external_paths
        For a path: the memory its reading may take (bytes, or ``"2G"``)
        and whether it may read files outside its folder (see :func:`load_mesh`).

    Returns
    -------
    Mesh
        The mesh; arrays are copied once, into the voxelizer's own storage.

    Raises
    ------
    ValueError
        Nothing here is a mesh, or its arrays are malformed.
    OSError
        A path that cannot be read.

    Examples
    --------
    >>> m = topovox.as_mesh(np.eye(3), [[0, 1, 2]])
    """
    m: Any = mesh_or_vertices
    if isinstance(m, Mesh):
        if faces is not None:
            raise ValueError("faces is given twice: by the Mesh and by faces=")
        return m
    if faces is None:
        if isinstance(m, (str, os.PathLike)):
            return load_mesh(os.fspath(m), allow_external_paths=allow_external_paths, max_memory=max_memory)
        if isinstance(m, tuple) and len(m) == 2:
            return as_mesh(m[0], m[1])
        if isinstance(getattr(m, "geometry", None), dict):  # a trimesh.Scene (what trimesh.load("x.glb") returns)
            m = m.to_geometry() if hasattr(m, "to_geometry") else m.dump(concatenate=True)
        if hasattr(m, "vertices") and hasattr(m, "faces"):
            return Mesh(_as_float_points(m.vertices, "vertices"), _as_index_array(m.faces, "faces"), **_trimesh_appearance(m))
        if hasattr(m, "vertices") and hasattr(m, "triangles"):
            has = getattr(m, "has_vertex_colors", None)
            vc = _colours(np.asarray(m.vertex_colors)) if callable(has) and has() else None
            return Mesh(
                _as_float_points(np.asarray(m.vertices), "vertices"),
                _as_index_array(np.asarray(m.triangles), "triangles"),
                vertex_colours=vc,
            )
        if hasattr(m, "vertex") and hasattr(m, "triangle"):  # open3d.t.geometry.TriangleMesh, the tensor API
            return _from_open3d_tensor(m)
        raise ValueError(
            "give a topovox.Mesh, a path, a trimesh mesh or scene, an Open3D TriangleMesh, "
            f"a (vertices, faces) pair, or vertices and faces arrays; got {type(m).__name__}"
        )
    return Mesh(_as_float_points(m, "vertices"), _as_index_array(faces, "faces"))


def voxelize(
    mesh_or_vertices: Union[MeshLike, np.ndarray],
    faces: Optional[Any] = None,
    *,
    mode: ModeName = "cover",
    resolution: Optional[int] = None,
    voxel_size: Optional[VoxelSizeLike] = None,
    origin: Optional[Sequence[float]] = None,
    dims: Optional[Sequence[int]] = None,
    pad: int = 0,
    fit: FitName = "box",
    method: MethodName = "auto",
    threads: Optional[int] = None,
    attributes: bool = False,
    colour_rule: ColourRuleName = "dominant",
    normals: bool = False,
    surface: Optional[ModeName] = None,
    fill: Optional[FillName] = None,
    hollow: Optional[int] = None,
    gpu_path: GpuPathName = "compute",
    seed: int = 0,
    tile: Optional[int] = None,
    max_memory: Optional[Union[int, str]] = None,
    up: UpName = "y",
    dither: bool = False,
    watertight: bool = True,
    triangulate: bool = False,
    block_palette: Optional[Union[str, os.PathLike[str]]] = None,
    allow_external_paths: bool = False,
    color_rule: Optional[ColourRuleName] = None,
) -> VoxelGrid:
    """Voxelizes a mesh with a stated topological guarantee.

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array
        (float64 or float32; other dtypes are converted) with ``faces``.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    mode : str
        One of :data:`MODES` (see the module documentation).
    resolution : int, optional
        The longest side of the bounding box spans this many voxels
        (default 128 when no grid option is given).
    voxel_size : float or (float, float, float), optional
        The voxel edge, or ``(sx, sy, sz)`` per axis; alone, the grid is
        fitted to the mesh.
    origin, dims : sequence, optional
        With ``voxel_size``, an explicit grid; triangles outside it are
        clipped, never wrapped.
    pad : int
        Empty voxels added on every side of a fitted grid.
    fit : {"box", "cube"}
        ``"box"``: the grid starts at the bounding box's corner; ``"cube"``:
        ``resolution**3`` voxels centred on the bounding box, its longest
        side spanning ``resolution - 2 * pad`` voxels (the ShapeNet/ModelNet
        convention).
    method : str
        One of :data:`METHODS`. ``auto`` picks the fastest path that gives
        the mode's exact voxels; every method gives the same voxels.
    threads : int, optional
        Worker threads (default: all cores).
    attributes : bool
        Also carry colours, material ids, coverage and normals from the
        mesh into the voxels (as ``--attributes`` does on the command
        line); ``normals=True`` carries them too.
    colour_rule : {"dominant", "blend"}
        The colour covering the most area, or the area-weighted mean in
        linear light; ``color_rule`` is the same option.
    surface : str, optional
        Solid modes: the surface of ``solid+surface`` and of a flood fill's
        shell (cover, sep26, sep6 or ss6).
    fill : {"flood"}, optional
        Solid modes: fill what a surface shell encloses.
    hollow : {6, 26}, optional
        Solid modes: keep the voxels 6- or 26-adjacent to the outside.
    gpu_path : {"compute", "raster", "msaa-approx"}
        With ``method="gpu"``.
    seed : int
        ``bubble``: the seed of the random target points (same seed, same
        voxels).
    tile : int, optional
        Run the surface or line mode tile by tile with tiles of this many
        voxels (a multiple of 8); same voxels. By default only grids that
        do not fit in ``max_memory`` run tiled.
    max_memory : int or str, optional
        Memory the run may use, bytes or a size such as ``"8G"`` (default:
        nine tenths of what is available). Tiled grids are sparse: use
        :meth:`VoxelGrid.coords` or ``save("x.vdb")`` rather than
        ``occupancy``.
    up, dither, watertight, triangulate, block_palette
        The writers' options, as :meth:`VoxelGrid.save` and :func:`batch`
        take them (accepted here so that every front end takes every
        option; :meth:`VoxelGrid.save` is where they apply).
    allow_external_paths : bool
        Read files a mesh given by path names outside its folder.

    Returns
    -------
    VoxelGrid
        The voxels, the grid and what the run did (``facts``).

    Raises
    ------
    ValueError
        Bad arguments or arrays (wrong shape, NaN, indices out of range),
        with the command line's message in Python's terms.
    RuntimeError
        The job could not run (no GPU, not enough memory).
    KeyboardInterrupt
        Ctrl-C: the run stops within a fraction of a second.

    Notes
    -----
    The GIL is released while voxelizing, so threads voxelize in parallel.

    Examples
    --------
    >>> grid = topovox.voxelize("bunny.obj", mode="sep6", resolution=64)
    >>> occupancy = np.asarray(grid)
    """
    mesh = as_mesh(mesh_or_vertices, faces, max_memory=max_memory, allow_external_paths=allow_external_paths)
    options = dict(locals())
    for k in ("mesh_or_vertices", "faces", "mesh"):
        options.pop(k)
    return _topovox.voxelize(mesh, _options(options))


def voxelize_many(
    meshes: Iterable[Any],
    *,
    features: Union[FeatureName, Sequence[FeatureName]] = ("occupancy",),
    on_error: Literal["raise", "skip"] = "raise",
    mode: ModeName = "cover",
    resolution: Optional[int] = None,
    voxel_size: Optional[VoxelSizeLike] = None,
    origin: Optional[Sequence[float]] = None,
    dims: Optional[Sequence[int]] = None,
    pad: int = 0,
    fit: FitName = "cube",
    method: MethodName = "auto",
    threads: Optional[int] = None,
    attributes: bool = False,
    colour_rule: ColourRuleName = "dominant",
    normals: bool = False,
    surface: Optional[ModeName] = None,
    fill: Optional[FillName] = None,
    hollow: Optional[int] = None,
    gpu_path: GpuPathName = "compute",
    seed: int = 0,
    tile: Optional[int] = None,
    max_memory: Optional[Union[int, str]] = None,
    up: UpName = "y",
    dither: bool = False,
    watertight: bool = True,
    triangulate: bool = False,
    block_palette: Optional[Union[str, os.PathLike[str]]] = None,
    allow_external_paths: bool = False,
    color_rule: Optional[ColourRuleName] = None,
    progress: Union[None, bool, Callable[[int, int], Any]] = None,
) -> SparseBatch:
    """Voxelizes many meshes in one call into one sparse training batch.

    Each item is exactly what :func:`voxelize` gives for that mesh alone
    with the same options (tested voxel for voxel); the work is spread
    over the meshes and within them, without the GIL.

    Parameters
    ----------
    meshes : iterable
        Paths, :class:`Mesh`\ es, trimesh or Open3D meshes, or
        ``(vertices, faces)`` pairs.
    features : str or sequence of str
        Per-voxel feature columns, in this order (see :data:`FEATURES`):
        ``occupancy`` (1), ``normal`` (3), ``colour`` (3, sRGB in [0, 1];
        ``color`` is the same), ``coverage`` (1), ``material`` (1, -1 for
        none), ``sdf`` (1: the signed distance from the voxel centre, world
        units, negative inside by the solid's rule, equal to ``topovox
        sdf --band all`` there).
    on_error : {"raise", "skip"}
        ``"raise"``: the first mesh that fails (by index) raises, its index
        and name in the message. ``"skip"``: it becomes an empty item and
        ``batch.errors[index]`` says why; the others are unaffected.
    fit : {"cube", "box"}
        ``"cube"`` (the default here): every item ``resolution**3`` voxels,
        the mesh centred (the ShapeNet/ModelNet convention).
    mode, resolution, voxel_size, origin, dims, pad, method, threads, ...
        As :func:`voxelize`. ``method="gpu"`` voxelizes the surface modes
        of the whole batch on the GPU in one upload and one dispatch (each
        mesh in its own layers of one tall grid), the same voxels as one
        call per mesh.
    progress : bool or callable, optional
        ``True``: ``finished/total meshes`` on one line of stderr while the
        meshes are voxelized; a callable is called as ``progress(finished,
        total)`` on the calling thread whenever the count changed (from the
        loop that watches for Ctrl-C; an exception it raises stops the
        batch). Off by default, as in a data loader's workers.

    Returns
    -------
    SparseBatch
        ``coords`` int32 ``(N, 4)`` ``[b, i, j, k]`` sorted by item then C
        order, ``features`` float32 ``(N, C)``, ``offsets`` ``(B + 1,)``,
        each item's grid (``origins``, ``voxel_sizes``, ``dims``,
        ``item(b)``), ``to_dense()`` and ``layout(library)``.

    Raises
    ------
    ValueError, OSError, RuntimeError
        As :func:`voxelize`, naming the mesh's index (``on_error="raise"``).

    Examples
    --------
    >>> batch = topovox.voxelize_many(paths, resolution=32, features=("occupancy", "normal"))
    >>> batch.coords.shape, batch.features.shape, batch.offsets
    >>> t = batch.layout("spconv")
    """
    if on_error not in ("raise", "skip"):
        raise ValueError(f"on_error must be 'raise' or 'skip'; got {on_error!r}")
    if isinstance(meshes, (str, os.PathLike, Mesh)):
        raise TypeError("voxelize_many takes a list of meshes; for one mesh, pass [mesh] (or call voxelize)")
    given: List[str] = [features] if isinstance(features, str) else [str(f) for f in features]
    names = ["colour" if f.lower() == "color" else f for f in given]
    options = dict(locals())
    for k in ("meshes", "features", "on_error", "given", "names", "progress"):
        options.pop(k)
    report = _stderr_progress("topovox voxelize_many") if progress is True else progress or None
    items = list(meshes)
    # Paths are read together, on all threads; with max_memory, one at a time, each within it.
    paths = [b for b, m in enumerate(items) if isinstance(m, (str, os.PathLike))] if max_memory is None else []
    read = dict(zip(paths, _topovox.load_meshes([items[b] for b in paths], allow_external_paths, threads)))
    loaded: List[Optional[Mesh]] = []
    failed: Dict[int, str] = {}
    for b, m in enumerate(items):
        try:
            r = read.get(b)
            if isinstance(r, BaseException):
                raise r
            loaded.append(r if r is not None else m if isinstance(m, Mesh) else as_mesh(*m) if isinstance(m, tuple) else as_mesh(m, max_memory=max_memory, allow_external_paths=allow_external_paths))
        except (ValueError, TypeError, OSError) as e:
            failed[b] = _item_error(b, m, e, on_error)
            loaded.append(None)
    out = _topovox.voxelize_many(loaded, _options(options), names, report)
    for b, exc in out["errors"]:
        failed[int(b)] = _item_error(int(b), loaded[int(b)], exc, on_error)
    return SparseBatch(out["coords"], out["features"], out["offsets"], out["grids"], out["columns"], failed)


def _item_error(b: int, m: Any, e: BaseException, on_error: str) -> str:
    """Item ``b``'s error, named by its index (and its path, or its type,
    when the message does not say): raised as it is
    (``on_error="raise"``), or its message returned to be kept."""
    if isinstance(m, (str, os.PathLike)):
        name = os.fsdecode(m)
    else:
        name = (m.path or "mesh") if isinstance(m, Mesh) else type(m).__name__
    message = f"mesh {b}: {e}" if name in str(e) else f"mesh {b} ({name}): {e}"
    if on_error == "raise":
        e.args = (message,)
        raise e
    return message


def sdf(
    mesh_or_vertices: Union[MeshLike, np.ndarray],
    faces: Optional[Any] = None,
    *,
    resolution: Optional[int] = None,
    voxel_size: Optional[VoxelSizeLike] = None,
    origin: Optional[Sequence[float]] = None,
    dims: Optional[Sequence[int]] = None,
    pad: int = 0,
    fit: FitName = "box",
    band: Union[float, Literal["all"]] = 3,
    unsigned: bool = False,
    sign: SignName = "auto",
    threads: Optional[int] = None,
    max_memory: Optional[Union[int, str]] = None,
    allow_external_paths: bool = False,
) -> DistanceGrid:
    """The distance field of a mesh, as ``topovox sdf`` computes it.

    Each voxel's value is the Euclidean distance, in world units, from its
    centre to the nearest point of the mesh (every triangle; degenerate
    ones as their edges; segments too), exact to float32 rounding. Signed
    fields are negative exactly on the voxels :func:`voxelize` with
    ``mode="solid"`` and the same ``method`` sets (the oriented mesh's
    nonzero winding number where closed, the generalized winding number
    otherwise).

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with
        ``faces``.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    resolution, voxel_size, origin, dims, pad, fit
        The grid, exactly as :func:`voxelize` takes it (same grid, same
        placement).
    band : float or "all"
        Half width of the stored band in voxels (default 3, as OpenVDB):
        voxels nearer than ``band * h`` get their distance, the others
        ``±band * h``, ``h`` the voxel edge (the largest of the three for
        boxes). ``"all"``: every voxel.
    unsigned : bool
        No sign: the unsigned distance (open meshes, polylines).
    sign : {"auto", "parity", "winding"}
        How inside is decided, as ``voxelize(mode="solid", method=...)``.
    threads : int, optional
        Worker threads (default: all cores).
    max_memory : int or str, optional
        Memory the run may use, bytes or a size such as ``"8G"``.
    allow_external_paths : bool
        Read files a mesh given by path names outside its folder.

    Returns
    -------
    DistanceGrid
        ``to_dense()`` (or ``numpy.asarray``), ``coords()`` and ``values()``
        of the band, ``save()``, and the grid's ``origin``,
        ``voxel_size`` and ``shape``.

    Raises
    ------
    ValueError
        Bad arguments, a band of 0 or below, NaN vertices, an empty mesh.
    RuntimeError
        Not enough memory for the grid.
    KeyboardInterrupt
        Ctrl-C: the run stops within a fraction of a second.

    Examples
    --------
    >>> field = topovox.sdf("bunny.obj", resolution=128, band=3)
    >>> field.save("bunny.vdb")
    """
    mesh = as_mesh(mesh_or_vertices, faces, max_memory=max_memory, allow_external_paths=allow_external_paths)
    options = dict(locals())
    for k in ("mesh_or_vertices", "faces", "mesh"):
        options.pop(k)
    return _topovox.sdf(mesh, _options(options))



class Query:
    """A mesh prepared for exact point queries, built once and shared by threads.

    Distances are the exact minimum of f64 point–triangle distances (a
    degenerate triangle counts as its edges; segments of a polyline count
    too), as :func:`sdf` measures them. Inside follows ``sign``:

    - ``"auto"`` (default): the winding number of the mesh oriented by
      parts and nesting (flipped faces do not matter; overlapping shells
      give their union, nested ones cavities): nonzero where closed, ``|w| >= 1/2`` otherwise — the rule
      ``voxelize(mode="solid")`` uses;
    - ``"parity"``: an odd number of crossings of a ray;
    - ``"winding"``: the winding number (exact integers on closed meshes).

    Every test is exact on the vertices as given, with the grids' tie rule
    (a point exactly on a face takes the side of the point displaced by
    ``-(ε, ε², ε³)``). The grids decide on vertices snapped to a 1/4096-voxel
    lattice, so at voxel centres ``contains`` equals ``voxelize(mode="solid")``
    whenever the vertices lie on that lattice, and otherwise can differ only
    at centres within about 1/8192 voxel of the surface.

    Points are ``(n, 3)`` (or one ``(3,)``) float64 or float32, any strides;
    results are float64. A point that is not finite gets NaN distances and
    winding numbers, is not inside, and has no closest triangle (-1). The
    GIL is released; ``threads`` caps the threads (default: all cores).
    Results do not depend on the thread count or the order of the points.

    Examples
    --------
    >>> q = topovox.Query("bunny.obj")
    >>> d = q.distance(points)            # signed: negative inside
    >>> inside = q.contains(points)
    >>> p, d, tri, bary = q.closest(points)
    """

    def __init__(self, mesh_or_vertices: Union[MeshLike, np.ndarray], faces: Optional[Any] = None, *, sign: SignName = "auto", threads: Optional[int] = None) -> None:
        self._q = _topovox.Query(as_mesh(mesh_or_vertices, faces), sign, threads)

    @staticmethod
    def _points(points: Any) -> Tuple[np.ndarray, bool]:
        a = _as_float_points(points, "points")
        one = a.ndim == 1
        return (a.reshape(1, -1) if one else a), one

    def distance(self, points: Any, signed: bool = True) -> Any:
        """The distance to the mesh at each point: ``(n,)`` float64, negative
        inside when ``signed`` (a point on the surface that counts as inside
        gets ``-2**-149``, as :func:`sdf` stores it)."""
        a, one = self._points(points)
        out = self._q.distance(a, signed)
        return out[0] if one else out

    def contains(self, points: Any) -> Any:
        """Whether each point is inside, by the query's ``sign``: ``(n,)`` bool."""
        a, one = self._points(points)
        out = self._q.contains(a) == 1.0
        return out[0] if one else out

    def winding_number(self, points: Any) -> Any:
        """The (generalized) winding number at each point: ``(n,)`` float64,
        an exact integer on a closed mesh."""
        a, one = self._points(points)
        out = self._q.winding_number(a)
        return out[0] if one else out

    def closest(self, points: Any) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The nearest point of the mesh to each point.

        Returns ``(points (n, 3), distances (n,), triangles (n,) int64,
        barycentric (n, 3))``: the triangle's index in the mesh (a polyline
        segment ``s`` is ``len(faces) + s``, its ends the first two weights);
        among equally near triangles the lowest index."""
        a, one = self._points(points)
        p, d, t, w = self._q.closest(a)
        if one:
            return p[0], d[0], t[0], w[0]
        return p, d, t, w

    @property
    def facts(self) -> Dict[str, Any]:
        """``elements``, ``skipped``, ``watertight``, ``boundary_cycles``,
        the ``sign`` rule ``"auto"`` resolved to, and (unless parity)
        ``orientation``: what orienting the mesh found and repaired
        (``parts``, ``closed_parts``, ``nested_parts``, ``sheets``,
        ``faces_reoriented``, ``unorientable_edges``)."""
        return self._q.facts


def distance(mesh_or_vertices: Union[MeshLike, np.ndarray], points: Any, *, faces: Optional[Any] = None, signed: bool = True, sign: SignName = "auto", threads: Optional[int] = None) -> Any:
    """The exact distance from each point to the mesh, negative inside when
    ``signed``: ``Query(mesh).distance(points, signed)`` in one call (see
    :class:`Query`; build a :class:`Query` once to ask many times).

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with ``faces``.
    points : array_like
        ``(n, 3)`` (or one ``(3,)``) float64 or float32, any strides.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    signed : bool
        Negative inside, by ``sign`` (default True).
    sign : {"auto", "parity", "winding"}
        The inside rule (see :class:`Query`).
    threads : int, optional
        Worker threads (default: all cores).

    Returns
    -------
    numpy.ndarray
        ``(n,)`` float64 (a float for one point); NaN for points that are not finite.

    Examples
    --------
    >>> d = topovox.distance("bunny.obj", points)
    """
    return Query(mesh_or_vertices, faces, sign=sign, threads=threads).distance(points, signed)


def contains(mesh_or_vertices: Union[MeshLike, np.ndarray], points: Any, *, faces: Optional[Any] = None, sign: SignName = "auto", threads: Optional[int] = None) -> Any:
    """Whether each point is inside the mesh, by the rule of
    ``voxelize(mode="solid")``: ``Query(mesh).contains(points)`` in one call
    (see :class:`Query`).

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with ``faces``.
    points : array_like
        ``(n, 3)`` (or one ``(3,)``) float64 or float32, any strides.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    sign : {"auto", "parity", "winding"}
        The inside rule (see :class:`Query`).
    threads : int, optional
        Worker threads (default: all cores).

    Returns
    -------
    numpy.ndarray
        ``(n,)`` bool (a bool for one point); False for points that are not finite.

    Examples
    --------
    >>> inside = topovox.contains("bunny.obj", points)
    """
    return Query(mesh_or_vertices, faces, sign=sign, threads=threads).contains(points)


def closest(mesh_or_vertices: Union[MeshLike, np.ndarray], points: Any, *, faces: Optional[Any] = None, threads: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The nearest point of the mesh to each point: ``Query(mesh).closest(points)``
    in one call (see :class:`Query`).

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with ``faces``.
    points : array_like
        ``(n, 3)`` (or one ``(3,)``) float64 or float32, any strides.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    threads : int, optional
        Worker threads (default: all cores).

    Returns
    -------
    tuple of numpy.ndarray
        ``points (n, 3)``, ``distances (n,)``, ``triangles (n,)`` int64 (-1 for
        points that are not finite) and ``barycentric (n, 3)``.

    Examples
    --------
    >>> p, d, tri, bary = topovox.closest("bunny.obj", points)
    """
    return Query(mesh_or_vertices, faces, threads=threads).closest(points)


def winding_number(mesh_or_vertices: Union[MeshLike, np.ndarray], points: Any, *, faces: Optional[Any] = None, threads: Optional[int] = None) -> Any:
    """The (generalized) winding number of the mesh at each point, an exact
    integer on a closed mesh: ``Query(mesh).winding_number(points)`` in one
    call (see :class:`Query`).

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with ``faces``.
    points : array_like
        ``(n, 3)`` (or one ``(3,)``) float64 or float32, any strides.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    threads : int, optional
        Worker threads (default: all cores).

    Returns
    -------
    numpy.ndarray
        ``(n,)`` float64 (a float for one point); NaN for points that are not finite.

    Examples
    --------
    >>> w = topovox.winding_number("bunny.obj", points)
    """
    return Query(mesh_or_vertices, faces, threads=threads).winding_number(points)


def sample(
    mesh_or_vertices: Union[MeshLike, np.ndarray],
    faces: Optional[Any] = None,
    *,
    surface: int = 0,
    near: int = 0,
    sigma: Union[float, Sequence[float]] = (0.005, 0.05),
    uniform: int = 0,
    bounds: Optional[Any] = None,
    normalize: Optional[Literal["unit-cube", "unit-sphere"]] = None,
    seed: int = 0,
    sign: SignName = "auto",
    threads: Optional[int] = None,
    max_memory: Optional[Union[int, str]] = None,
    allow_external_paths: bool = False,
    dtype: Any = np.float32,
) -> Dict[str, Any]:
    """Training samples: points on, near and around the mesh with their
    signed distance and occupancy (the :class:`Query`'s, so ``sdf < 0``
    exactly where ``occupancy``).

    Parameters
    ----------
    surface : int
        Points uniform on the surface (by area), with their triangle's unit normal.
    near : int
        Surface points moved by an isotropic Gaussian, each standard
        deviation of ``sigma`` in turn (DeepSDF's near-surface samples,
        IF-Net's boundary sampling).
    sigma : float or sequence of floats
        The Gaussians' standard deviations, in the units of the (normalized) mesh.
    uniform : int
        Points uniform in ``bounds`` (Occupancy Networks' box samples).
    bounds : ``(2, 3)`` array_like, optional
        The box ``[low, high]``; default: the (normalized) mesh's box grown
        by 5 % of its longest side on every side.
    normalize : {"unit-cube", "unit-sphere", None}
        Move the box centre to the origin and scale the longest side to 1
        (``"unit-cube"``) or the farthest vertex to distance 1
        (``"unit-sphere"``) first; ``offset`` and ``scale`` in the result
        map back: ``original = points / scale + offset``.
    seed : int
        The same seed gives the same samples on any machine and thread count.
    sign, threads
        As :class:`Query`.
    max_memory, allow_external_paths
        As :func:`voxelize`: a count of samples that needs more memory is
        refused before any work.
    dtype : {numpy.float32, numpy.float64}
        The type of ``points``, ``sdf`` and ``normals``: float32 (the
        default, as ``topovox sample`` writes them and as models train), or
        float64 for the exact values computed (float32 is their rounding).

    Returns
    -------
    dict
        ``points`` (N, 3) ``dtype`` — surface points first, then near, then
        uniform; ``sdf`` (N,) ``dtype``; ``occupancy`` (N,) bool; ``normals``
        (N, 3) ``dtype`` (NaN except for surface points); ``kind`` (N,) uint8
        (0 surface, 1 near, 2 uniform); ``colours`` (N, 3) float32, sRGB
        in [0, 1] (NaN except for surface points), only when the mesh has
        colours (a texture's nearest texel, vertex colours interpolated,
        the material's colour); ``offset`` (3,), ``scale`` and ``bounds``
        (2, 3); ``info``: counts, the sign rule, times.

    Examples
    --------
    DeepSDF's recipe (250 k points per sigma near the surface, in the unit sphere):

    >>> s = topovox.sample("bunny.obj", near=500_000, sigma=(0.05, 0.0158),
    ...                    normalize="unit-sphere", seed=1)
    """
    kind = np.dtype(dtype)
    if kind not in (np.float32, np.float64):
        raise ValueError(f"dtype must be float32 or float64; got {kind}")
    mesh = as_mesh(mesh_or_vertices, faces, max_memory=max_memory, allow_external_paths=allow_external_paths)
    options = dict(locals())
    for k in ("mesh_or_vertices", "faces", "mesh", "dtype", "kind"):
        options.pop(k)
    if options["bounds"] is not None:
        options["bounds"] = np.asarray(options["bounds"], dtype=np.float64).reshape(-1).tolist()
    out = _topovox.sample(mesh, _options(options))
    out["occupancy"] = out["occupancy"].astype(bool)
    for k in ("points", "sdf", "normals"):
        out[k] = out[k].astype(kind, copy=False)
    return out

def remesh(
    mesh_or_vertices: Union[MeshLike, np.ndarray],
    faces: Optional[Any] = None,
    *,
    resolution: Optional[int] = None,
    voxel_size: Optional[VoxelSizeLike] = None,
    origin: Optional[Sequence[float]] = None,
    dims: Optional[Sequence[int]] = None,
    pad: Optional[int] = None,
    fit: FitName = "box",
    inside: InsideName = "auto",
    surface: SurfaceKindName = "smooth",
    min_part: int = 0,
    simplify: float = 0.0,
    check: bool = False,
    threads: Optional[int] = None,
    max_memory: Optional[Union[int, str]] = None,
    allow_external_paths: bool = False,
    info: Optional[Dict[str, Any]] = None,
) -> Mesh:
    """A watertight mesh of a mesh, as ``topovox remesh`` makes it.

    The surface closes around voxels: those :func:`voxelize` with
    ``mode="solid"`` sets by the same rule, or with ``inside="wrap"``
    shells around any input. By construction it is closed (every edge in
    two faces), 2-manifold, oriented with normals outwards, free of
    self-intersections and zero-area faces, and separates exactly: every
    inside voxel centre has winding number 1, every other 0. Every part is
    kept unless ``min_part`` drops small ones.

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with
        ``faces``.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.
    resolution, voxel_size, origin, dims, pad, fit
        The grid, exactly as :func:`voxelize` takes it (``inside="wrap"``
        pads a fitted grid by one voxel unless ``pad`` is given).
    inside : {"auto", "parity", "winding", "wrap"}
        Which voxels the surface closes around: the solid by that method,
        or ``"wrap"``: the solid, the conservative cover grown by one voxel
        and every cavity they enclose, so sheets, open surfaces, thin walls
        and loose parts become closed shells containing the whole input.
    surface : {"smooth", "blocky"}
        ``"smooth"``: vertices where the exact signed distance crosses zero
        along the lattice edges (marching tetrahedra); ``"blocky"``: on
        the inside voxels' faces.
    min_part : int
        Drop inside parts (26-connected) of fewer voxels (default 0).
    simplify : float
        Merge faces while each vertex kept stays within this many voxels
        (0 to 2) of the planes merged into it (default 0: none). A collapse
        that would break a guarantee above is refused, and the result is
        certified again; ``info["simplify"]`` reports the faces before and
        after.
    check : bool
        Certify the result exactly before returning it (see
        :func:`check_mesh`); the certificate goes into ``info``.
    threads, max_memory, allow_external_paths
        As :func:`voxelize`.
    info : dict, optional
        Filled with the summary: ``inside``, ``inside_voxels``, ``parts``,
        timings, ``distance_voxels`` (wrap and check) and ``certificate``.

    Returns
    -------
    Mesh
        ``vertices``, ``faces``, ``save(path)``, ``to_trimesh()``.

    Raises
    ------
    ValueError
        Bad arguments, an empty mesh, non-finite vertices, nothing inside.
    RuntimeError
        Not enough memory for the grid.

    Examples
    --------
    >>> closed = topovox.remesh("bunny.obj", resolution=256)
    >>> closed.save("bunny-closed.ply")
    """
    mesh = as_mesh(mesh_or_vertices, faces, max_memory=max_memory, allow_external_paths=allow_external_paths)
    options = dict(locals())
    for k in ("mesh_or_vertices", "faces", "mesh", "info"):
        options.pop(k)
    out, facts = _topovox.remesh(mesh, _options(options))
    if info is not None:
        info.update(facts)
    return out


def check_mesh(mesh_or_vertices: Union[MeshLike, np.ndarray], faces: Optional[Any] = None) -> Dict[str, Any]:
    """The certificate of any triangle mesh, as ``topovox check MESH``.

    Vertices with bit-identical coordinates count as one. Each property is
    decided exactly (integer lattice arithmetic, Shewchuk's predicates):
    ``closed``, ``manifold``, ``oriented``, ``watertight`` (all of them,
    no self-intersection, no degenerate face, positive volume), and the
    counts ``boundary_edges``, ``non_manifold_edges``,
    ``non_manifold_vertices``, ``inconsistent_edges``,
    ``self_intersections`` (face pairs; the first in
    ``intersecting_pairs``), ``degenerate_faces``, ``components``,
    ``euler``, ``genus`` (closed, oriented, manifold meshes) and ``volume``.

    Parameters
    ----------
    mesh_or_vertices : Mesh, path, trimesh or Open3D mesh, or array_like
        Anything :func:`as_mesh` takes, or an ``(n, 3)`` vertex array with
        ``faces``.
    faces : array_like, optional
        ``(m, 3)`` integer vertex indices, when vertices are given.

    Returns
    -------
    dict
        The certificate (the keys above).

    Raises
    ------
    ValueError
        A mesh without faces, non-finite vertices.

    Examples
    --------
    >>> topovox.check_mesh("bunny.obj")["closed"]
    False
    """
    return dict(_topovox.check_mesh(as_mesh(mesh_or_vertices, faces)))


def _options(options: Dict[str, Any]) -> Dict[str, Any]:
    """Keyword options as the native side takes them: ``None`` left out,
    ``color_rule`` spelled ``colour_rule``, paths as strings. Every value is
    checked there, by the job crate, with the command line's rules."""
    out = {k: v for k, v in options.items() if v is not None}
    if "color_rule" in out:
        out["colour_rule"] = out.pop("color_rule")
    if "block_palette" in out:
        out["block_palette"] = os.fsdecode(out["block_palette"])
    return out


def batch(
    paths: Union[str, os.PathLike[str], Iterable[Union[str, os.PathLike[str]]]],
    out_dir: Union[str, os.PathLike[str]],
    *,
    format: Optional[str] = None,
    glob: Optional[str] = None,
    jobs: Optional[int] = None,
    progress: Union[None, bool, Callable[[int, int], Any]] = None,
    run: Literal["voxelize", "sdf", "remesh", "sample"] = "voxelize",
    **options: Any,
) -> Dict[str, Any]:
    """Voxelizes whole datasets, resumably, as ``topovox batch`` does.

    One output per input, named after the input's path below the inputs'
    common folder with the format's extension; a manifest
    ``out_dir/manifest.jsonl`` (one JSON line per mesh: input, output,
    status, options, grid, voxels, times, error) written as it goes; meshes
    already done with the same options are skipped, so an interrupted batch
    resumes (from any front end); a bad mesh is recorded and the batch goes
    on. The output folder and files a manifest lists as outputs are never
    read as inputs.

    Parameters
    ----------
    paths : path or iterable of paths
        Files, or folders walked for meshes.
    out_dir : path
        The output folder.
    format : str, optional
        One of :data:`FORMATS` (default ``"npy"``); with ``run="sdf"``
        ``"npy"``, ``"vdb"``, ``"zarr"`` or ``"vti"`` (default ``"npy"``);
        with ``run="remesh"`` ``"obj"``, ``"ply"``, ``"stl"`` or ``"glb"``
        (default ``"obj"``); with ``run="sample"`` ``"npz"``.
    glob : str, optional
        Which files of the folders to take, such as ``"**/*.obj"``.
    jobs : int, optional
        Meshes run at once (default: all cores).
    progress : bool or callable, optional
        ``True`` shows ``finished/total meshes`` on stderr, as the CLI's
        bar; a callable is called as ``progress(finished, total)`` on the
        calling thread as meshes finish (at most every 50 ms, and once at
        the end; meshes skipped as done count as finished). An exception it
        raises stops the batch as Ctrl-C does.
    run : {"voxelize", "sdf", "remesh", "sample"}
        What runs on each mesh: :func:`voxelize`, :func:`sdf` (a distance
        field per mesh), :func:`remesh` (a watertight mesh per mesh) or
        :func:`sample` (training samples per mesh, ``.npz``: the arrays
        ``topovox sample`` writes).
    **options
        Every option :func:`voxelize` takes (:data:`OPTIONS`), or with
        ``run="sdf"`` every option :func:`sdf` takes (``band``, ``sign``,
        ``unsigned`` and the grid's), or with ``run="remesh"`` every option
        :func:`remesh` takes (``inside``, ``surface``, ``min_part``,
        ``check`` and the grid's), or with ``run="sample"`` every option
        :func:`sample` takes (``surface``, ``near``, ``sigma``, ``uniform``,
        ``bounds``, ``normalize``, ``seed``, ``sign``); ``attributes=True`` writes every
        attribute grid into ``.vdb`` and ``.zarr`` outputs.

    Returns
    -------
    dict
        ``{"done", "skipped", "failed", "total_s", "manifest", "warnings"}``
        (warnings: links skipped because they loop).

    Raises
    ------
    ValueError
        Bad options, or the same input given twice.
    FileNotFoundError
        An input that does not exist.
    FileExistsError
        ``out_dir`` holds outputs an earlier batch wrote with other options
        (the message names them); nothing is replaced.
    NotADirectoryError
        A file stands where ``out_dir`` should be.

    Examples
    --------
    >>> topovox.batch("meshes/", "voxels/", resolution=64, fit="cube", progress=True)
    """
    if isinstance(paths, (str, bytes, os.PathLike)):
        paths = [paths]
    opts = _options(dict(options, jobs=jobs, run=run))
    # fsdecode: str and bytes paths alike (names that are not UTF-8 survive).
    report = _stderr_progress() if progress is True else progress or None
    return _topovox.batch([os.fsdecode(p) for p in paths], os.fsdecode(out_dir), format=format, glob=glob, options=opts, progress=report)


def _stderr_progress(label: str = "topovox batch") -> Callable[[int, int], None]:
    """``finished/total meshes`` on one line of stderr, as the CLI shows it."""
    import sys
    import time

    start = time.monotonic()

    def show(finished: int, total: int) -> None:
        end = "\n" if finished >= total else ""
        sys.stderr.write(f"\r{label}: {finished}/{total} meshes ({time.monotonic() - start:.1f} s){end}")
        sys.stderr.flush()

    return show
