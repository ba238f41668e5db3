"""Interoperability check: topovox's outputs read by real third-party readers.

NumPy reads the .npy files; the `binvox` package from PyPI reads the
.binvox file; both must hold exactly the voxels of topovox's text list, with
the grid placement reported by `--json`. For the textured spot: VTK's own
XML reader (`vtk` package) reads the .vti, `nbtlib` the .schem, `plyfile`
the point cloud and `pygltflib` the .glb; each must agree with the .npy and
with each other on voxels and colours. Prints 'N passed, M failed'.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from oracle import Oracle, text_voxels
from binvox import Binvox

TOPOVOX = sys.argv[1]
MESHES = Path(sys.argv[2])
ORACLE = Oracle(TOPOVOX)
check, voxelize = ORACLE.check, ORACLE.voxelize


with tempfile.TemporaryDirectory() as d:
    d = Path(d)
    for mesh, res in [("cow.obj", 48), ("suzanne.obj", 37), ("stanford-bunny.obj", 64)]:
        m = MESHES / mesh
        summary = voxelize(m, d / "v.npy", "--resolution", str(res))
        voxelize(m, d / "b.npy", "--resolution", str(res), "--format", "npy-bool")
        voxelize(m, d / "v.binvox", "--resolution", str(res))
        voxelize(m, d / "v.txt", "--resolution", str(res))
        want = set(map(tuple, text_voxels(d / "v.txt").tolist()))
        nx, ny, nz = summary["dims"]

        a = np.load(d / "v.npy")
        check(f"{mesh} npy shape", a.shape == (nx, ny, nz), a.shape)
        check(f"{mesh} npy dtype uint8", a.dtype == np.uint8, a.dtype)
        check(f"{mesh} npy values 0/1", set(np.unique(a).tolist()) <= {0, 1})
        check(f"{mesh} npy [i,j,k] = text voxels", set(map(tuple, np.argwhere(a).tolist())) == want)
        check(f"{mesh} npy count = summary", int(a.sum()) == summary["voxels"])
        b = np.load(d / "b.npy")
        check(f"{mesh} npy-bool dtype", b.dtype == np.bool_, b.dtype)
        check(f"{mesh} npy-bool equals uint8", np.array_equal(b, a.astype(bool)))

        bv = Binvox.read(str(d / "v.binvox"), "dense")
        side = max(nx, ny, nz)
        check(f"{mesh} binvox dims", list(bv.dims) == [side] * 3, bv.dims)
        check(f"{mesh} binvox translate", np.allclose(bv.translate, summary["origin"], rtol=0, atol=1e-12), bv.translate)
        check(f"{mesh} binvox scale", abs(bv.scale - side * summary["voxel_size"]) < 1e-12, bv.scale)
        data = np.asarray(bv.data)
        check(f"{mesh} binvox voxels (binvox package, xyz order)", np.array_equal(data[:nx, :ny, :nz], a.astype(bool)) and int(data.sum()) == int(a.sum()))

    # Coloured formats on the textured spot.
    spot = MESHES / "spot-textured.obj"
    summary = voxelize(spot, d / "s.npy", "--resolution", "64")
    for ext in ["vti", "schem", "ply", "glb", "vox"]:
        voxelize(spot, d / f"s.{ext}", "--resolution", "64")
    occ = np.load(d / "s.npy").astype(bool)
    nx, ny, nz = summary["dims"]

    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkXMLImageDataReader()
    r.SetFileName(str(d / "s.vti"))
    r.Update()
    img = r.GetOutput()
    check("vti dims (points) via VTK", img.GetDimensions() == (nx + 1, ny + 1, nz + 1), img.GetDimensions())
    check("vti origin and spacing via VTK", np.allclose(img.GetOrigin(), summary["origin"]) and np.allclose(img.GetSpacing(), [summary["voxel_size"]] * 3))
    cells = img.GetCellData()
    vocc = vtk_to_numpy(cells.GetArray("occupancy")).reshape(nz, ny, nx).transpose(2, 1, 0)
    check("vti occupancy = npy", np.array_equal(vocc.astype(bool), occ))
    # A voxel size per axis: VTK's Spacing, and the voxels of the .npy.
    boxes = voxelize(spot, d / "b.npy", "--voxel-size", "0.02,0.035,0.05", "--mode", "sep6")
    voxelize(spot, d / "b.vti", "--voxel-size", "0.02,0.035,0.05", "--mode", "sep6")
    rb = vtk.vtkXMLImageDataReader()
    rb.SetFileName(str(d / "b.vti"))
    rb.Update()
    bimg = rb.GetOutput()
    bx, by, bz = boxes["dims"]
    bocc = vtk_to_numpy(bimg.GetCellData().GetArray("occupancy")).reshape(bz, by, bx).transpose(2, 1, 0)
    check("vti of boxes: VTK's spacing per axis", np.allclose(bimg.GetSpacing(), boxes["voxel_size"]) and boxes["voxel_size"] == [0.02, 0.035, 0.05], bimg.GetSpacing())
    check("vti of boxes: occupancy = npy", np.array_equal(bocc.astype(bool), np.load(d / "b.npy").astype(bool)))
    vcol = vtk_to_numpy(cells.GetArray("colour")).reshape(nz, ny, nx, 3).transpose(2, 1, 0, 3)
    cov = vtk_to_numpy(cells.GetArray("coverage")).reshape(nz, ny, nx).transpose(2, 1, 0)
    check("vti coverage > 0 only on voxels", bool((cov[~occ] == 0).all()) and float(cov[occ].mean()) > 0.1)
    mat = vtk_to_numpy(cells.GetArray("material")).reshape(nz, ny, nx).transpose(2, 1, 0)
    check("vti material 0 on voxels, -1 elsewhere", bool((mat[occ] == 0).all()) and bool((mat[~occ] == -1).all()))

    from plyfile import PlyData
    ply = PlyData.read(str(d / "s.ply"))["vertex"]
    o, s = np.array(summary["origin"]), summary["voxel_size"]
    ijk = np.floor((np.stack([ply["x"], ply["y"], ply["z"]], 1) - o) / s).astype(int)
    pocc = np.zeros_like(occ)
    pocc[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
    check("ply point cloud voxels = npy (plyfile)", len(ijk) == occ.sum() and np.array_equal(pocc, occ))
    pcol = np.stack([ply["red"], ply["green"], ply["blue"]], 1)
    check("ply colours = vti colours", np.array_equal(pcol, vcol[ijk[:, 0], ijk[:, 1], ijk[:, 2]]))
    check("spot has more than 4 distinct colours", len(np.unique(pcol, axis=0)) > 4)

    import nbtlib
    sch = nbtlib.load(str(d / "s.schem"))
    root = sch["Schematic"] if "Schematic" in sch else sch
    check("schem version 2 (nbtlib)", int(root["Version"]) == 2)
    w, h, l = int(root["Width"]), int(root["Height"]), int(root["Length"])
    # --up y (the default): the mesh's y is Minecraft's height, block (x, y, z) = voxel (i, j, k).
    check("schem size: Height = the y extent (up y)", (w, h, l) == (nx, ny, nz), (w, h, l))
    meta = root.get("Metadata")
    check("schem Metadata WEOffsetX/Y/Z (mcschematic)", meta is not None and all(k in meta for k in ("WEOffsetX", "WEOffsetY", "WEOffsetZ")))
    pal = {str(k): int(v) for k, v in root["Palette"].items()}
    check("schem palette max", int(root["PaletteMax"]) == len(pal))

    def schem_blocks(root, pal):
        w, h, l = int(root["Width"]), int(root["Height"]), int(root["Length"])
        data = bytes(np.asarray(root["BlockData"], dtype=np.int8).astype(np.uint8))
        ids, v, shift = [], 0, 0
        for byte in data:
            v |= (byte & 0x7F) << shift
            shift += 7
            if byte < 0x80:
                ids.append(v)
                v, shift = 0, 0
        ids = np.array(ids).reshape(h, l, w)
        return (ids != pal["minecraft:air"]).transpose(2, 0, 1)  # [x][y][z]

    check("schem blocks = npy voxels (up y: [x][y][z] = [i][j][k])", np.array_equal(schem_blocks(root, pal), occ))
    # --up z: block (x, y, z) = voxel (i, k, ny-1-j), a rotation about x.
    voxelize(spot, d / "z.schem", "--resolution", "64", "--up", "z")
    rz = nbtlib.load(str(d / "z.schem"))
    rz = rz["Schematic"] if "Schematic" in rz else rz
    bz = schem_blocks(rz, {str(k): int(v) for k, v in rz["Palette"].items()})
    check("schem up z: [x][y][z] = [i][k][ny-1-j]", np.array_equal(bz[:, :, ::-1].transpose(0, 2, 1), occ))

    from pygltflib import GLTF2
    g = GLTF2().load(str(d / "s.glb"))
    prim = g.meshes[0].primitives[0]
    check("glb has positions, normals and COLOR_0 (pygltflib)", prim.attributes.POSITION is not None and prim.attributes.NORMAL is not None and prim.attributes.COLOR_0 is not None)
    acc = g.accessors[prim.attributes.POSITION]
    hi = np.array(summary["origin"]) + np.array([nx, ny, nz]) * s
    check("glb bounds inside the grid", np.all(np.array(acc.min) >= np.array(summary["origin"]) - 1e-5) and np.all(np.array(acc.max) <= hi + 1e-5))

    # .vox, parsed here from the published format (MagicaVoxel-file-format-vox.txt
    # and -extension.txt), independently of the dot_vox crate topovox uses.
    import struct
    raw = (d / "s.vox").read_bytes()
    check("vox magic and version 150", raw[:4] == b"VOX " and struct.unpack("<i", raw[4:8])[0] == 150)
    chunks, at = [], 20  # skip the MAIN header (id, content size, children size)
    while at < len(raw):
        cid, n, m = raw[at:at + 4], *struct.unpack("<ii", raw[at + 4:at + 12])
        chunks.append((cid, raw[at + 12:at + 12 + n]))
        at += 12 + n + m
    sizes = [struct.unpack("<iii", c) for i, c in chunks if i == b"SIZE"]
    xyzis = [c for i, c in chunks if i == b"XYZI"]
    rgba = [c for i, c in chunks if i == b"RGBA"]
    check("vox has one SIZE per XYZI and a 256-entry RGBA", len(sizes) == len(xyzis) == 1 and len(rgba) == 1 and len(rgba[0]) == 1024)
    # --up y (the default): MagicaVoxel (x, y, z) = voxel (i, nz-1-k, j), z up.
    check("vox model size = grid rotated to z up", sizes[0] == (nx, nz, ny), sizes[0])
    check("vox of one model has no scene graph", not ({i for i, _ in chunks} & {b"nTRN", b"nGRP", b"nSHP"}))
    pal = np.frombuffer(rgba[0], dtype=np.uint8).reshape(256, 4)
    n = struct.unpack("<i", xyzis[0][:4])[0]
    vx = np.frombuffer(xyzis[0][4:4 + 4 * n], dtype=np.uint8).reshape(n, 4).astype(int)
    check("vox colour indices in 1..255", bool((vx[:, 3] >= 1).all()))
    ijk = np.stack([vx[:, 0], vx[:, 2], nz - 1 - vx[:, 1]], 1)
    vocc2 = np.zeros_like(occ)
    vocc2[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
    check("vox voxels = npy", n == occ.sum() and np.array_equal(vocc2, occ))
    # RGBA entry k is colour index k + 1.
    vox_rgb = pal[vx[:, 3] - 1, :3]
    want_rgb = vcol[ijk[:, 0], ijk[:, 1], ijk[:, 2]]
    check("vox colours = vti colours (fewer than 256 colours: exact palette)", np.array_equal(vox_rgb, want_rgb))
    # py-vox-io (which reads single-model files) sees the same model.
    from pyvox.parser import VoxParser
    dense = VoxParser(str(d / "s.vox")).parse().to_dense()
    check("vox read by py-vox-io", int((dense > 0).sum()) == int(occ.sum()) and sorted(dense.shape) == sorted((nx, ny, nz)), dense.shape)

    # The mesh of the voxels is watertight (trimesh, vertices merged): no
    # edge used by a single face; a solid box is watertight outright.
    import trimesh
    voxelize(MESHES / "stanford-bunny.obj", d / "b.obj", "--resolution", "128")
    tm = trimesh.load(str(d / "b.obj"), force="mesh", process=True)
    counts = np.unique(tm.edges_sorted, axis=0, return_counts=True)[1]
    check("bunny voxel mesh: no edge used once (trimesh)", int((counts == 1).sum()) == 0, int((counts == 1).sum()))
    voxelize(MESHES / "cow.obj", d / "c.obj", "--resolution", "32", "--mode", "solid", "--triangulate")
    tc = trimesh.load(str(d / "c.obj"), force="mesh", process=True)
    counts = np.unique(tc.edges_sorted, axis=0, return_counts=True)[1]
    check("cow solid voxel mesh, triangulated: every edge used an even number of times", bool((counts % 2 == 0).all()))
    cs = voxelize(MESHES / "cow.obj", d / "c.npy", "--resolution", "32", "--mode", "solid")
    vol = cs["voxels"] * cs["voxel_size"] ** 3
    check("cow solid voxel mesh encloses exactly the voxels' volume (trimesh)", abs(tc.volume - vol) < 1e-9 + 1e-6 * vol, (tc.volume, vol))

    # Zarr v3: the `zarr` package opens it as one array equal to the .npy,
    # Dask reads it chunk by chunk; a tiled run's array has topovox's count.
    import zarr
    import dask.array as da
    s = voxelize(MESHES / "stanford-bunny.obj", d / "b.zarr", "--resolution", "300")
    voxelize(MESHES / "stanford-bunny.obj", d / "b.npy", "--resolution", "300")
    z = zarr.open_array(str(d / "b.zarr"), mode="r")
    check("zarr: shape, bool, 64³ chunks", z.shape == tuple(s["dims"]) and z.dtype == bool and z.chunks == (64, 64, 64), (z.shape, z.dtype, z.chunks))
    check("zarr: sharded, shards of at most 512 in whole chunks", all(c % 64 == 0 and c <= 512 for c in z.shards), z.shards)
    check("zarr: every voxel = the .npy", np.array_equal(z[:], np.load(d / "b.npy") > 0))
    check("zarr: grid placement in attributes", z.attrs["topovox"]["voxel_size"] == s["voxel_size"] and z.attrs["topovox"]["origin"] == s["origin"])
    s = voxelize(MESHES / "stanford-bunny.obj", d / "t.zarr", "--resolution", "2048", "--mode", "sep6", "--tile", "256")
    n = int(da.from_zarr(str(d / "t.zarr")).sum().compute())
    check("zarr: tiled sep6 at 2048 read by Dask has topovox's count", s["method"] == "tiled" and n == s["voxels"], (n, s["voxels"]))

    # --attributes: a Zarr group of `voxels` and attribute arrays with the
    # same chunking, equal to the .vti arrays VTK read above (same run);
    # Dask opens each array by component.
    s = voxelize(spot, d / "s.zarr", "--resolution", "64", "--attributes")
    voxelize(spot, d / "sn.vti", "--resolution", "64", "--normals")
    rn = vtk.vtkXMLImageDataReader()  # a reader of its own: the arrays above are views into r's output
    rn.SetFileName(str(d / "sn.vti"))
    rn.Update()
    vnorm = vtk_to_numpy(rn.GetOutput().GetCellData().GetArray("normal")).reshape(nz, ny, nx, 3).transpose(2, 1, 0, 3).copy()
    g = zarr.open_group(str(d / "s.zarr"), mode="r")
    check("zarr attributes: a group with voxels, colour, normal, coverage, material",
          sorted(g.array_keys()) == ["colour", "coverage", "material", "normal", "voxels"], sorted(g.array_keys()))
    check("zarr attributes: voxels = npy", np.array_equal(g["voxels"][:], occ))
    check("zarr attributes: colour (uint8, last axis 3) = vti", g["colour"].dtype == np.uint8 and np.array_equal(g["colour"][:], vcol), g["colour"].shape)
    check("zarr attributes: coverage = vti", np.array_equal(g["coverage"][:], cov))
    check("zarr attributes: material (int32, -1 elsewhere) = vti", g["material"].dtype == np.int32 and np.array_equal(g["material"][:], mat))
    check("zarr attributes: normal = vti --normals", np.array_equal(g["normal"][:], vnorm))
    check("zarr attributes: same chunking as voxels", g["coverage"].chunks == g["voxels"].chunks and g["colour"].chunks == g["voxels"].chunks + (3,), g["colour"].chunks)
    dc = da.from_zarr(str(d / "s.zarr"), component="colour")
    check("zarr attributes: Dask reads the colour array", np.array_equal(dc.compute(), vcol))

    # .npz of sparse coordinates: NumPy's own loader reads the (k, 3)
    # indices and the grid; scattered into a grid they equal the .npy; a
    # tiled run past --max-memory writes one too, with topovox's count.
    s = voxelize(MESHES / "stanford-bunny.obj", d / "b.npz", "--resolution", "300")
    with np.load(d / "b.npz") as z:
        idx, dims = z["indices"], z["dims"]
        check("npz: members, (k, 3) int32 indices", sorted(z.files) == ["dims", "indices", "origin", "voxel_size"] and idx.shape == (s["voxels"], 3) and idx.dtype == np.int32, (z.files, idx.shape, idx.dtype))
        grid = np.zeros(tuple(dims), bool)
        grid[tuple(idx.T)] = True
        check("npz: indices scattered into dims = the .npy", tuple(dims) == tuple(s["dims"]) and np.array_equal(grid, np.load(d / "b.npy") > 0))
        check("npz: placement", float(z["voxel_size"]) == s["voxel_size"] and list(z["origin"]) == s["origin"], (z["voxel_size"], z["origin"]))
        order = idx[:, 2].astype(np.int64) * dims[1] * dims[0] + idx[:, 1].astype(np.int64) * dims[0] + idx[:, 0]
        check("npz: ordered by k, then j, then i", bool((np.diff(order) > 0).all()))
    s = voxelize(MESHES / "stanford-bunny.obj", d / "t.npz", "--resolution", "3000", "--max-memory", "64M")
    with np.load(d / "t.npz") as z:
        check("npz: tiled run past --max-memory has topovox's count", s["method"] == "tiled" and z["indices"].shape[0] == s["voxels"], (s["method"], z["indices"].shape, s["voxels"]))

ORACLE.finish()
