//! Writing: the byte sink (a writer, or a counter), metadata, the grid
//! heads, the tree node by node, and the bool and attribute grids.

use super::*;

/// A byte sink: a writer, or a counter of the bytes a writer would get.
pub(super) trait Out {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()>;
    /// Puts the `len` bytes `fill` appends to a buffer; a counter adds
    /// `len` without calling it.
    fn put_with(&mut self, len: usize, fill: &mut dyn FnMut(&mut Vec<u8>) -> std::io::Result<()>) -> std::io::Result<()> {
        let mut buf = Vec::with_capacity(len);
        fill(&mut buf)?;
        // The counting pass took `len`: a mismatch would misplace every
        // later offset, so it is an error, never a corrupt file.
        if buf.len() != len {
            return Err(std::io::Error::other(format!("vdb writer: {} bytes where {len} were counted", buf.len())));
        }
        self.put(&buf)
    }
}

pub(super) struct Count(u64);

impl Out for Count {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.0 += b.len() as u64;
        Ok(())
    }
    fn put_with(&mut self, len: usize, _: &mut dyn FnMut(&mut Vec<u8>) -> std::io::Result<()>) -> std::io::Result<()> {
        self.0 += len as u64;
        Ok(())
    }
}

pub(super) struct Stream<'a>(&'a mut dyn Write);

impl Out for Stream<'_> {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.0.write_all(b)
    }
}

pub(super) fn put_str(o: &mut dyn Out, s: &str) -> std::io::Result<()> {
    o.put(&(s.len() as u32).to_le_bytes())?;
    o.put(s.as_bytes())
}

pub(super) fn put_words(o: &mut dyn Out, words: &[u64]) -> std::io::Result<()> {
    let mut buf = [0u8; 512];
    for chunk in words.chunks(64) {
        for (n, w) in chunk.iter().enumerate() {
            buf[8 * n..8 * n + 8].copy_from_slice(&w.to_le_bytes());
        }
        o.put(&buf[..8 * chunk.len()])?;
    }
    Ok(())
}

/// One metadata entry: name, type name, byte size, value.
pub(super) fn put_meta(o: &mut dyn Out, name: &str, ty: &str, value: &[u8]) -> std::io::Result<()> {
    put_str(o, name)?;
    put_str(o, ty)?;
    o.put(&(value.len() as u32).to_le_bytes())?;
    o.put(value)
}

pub(super) fn vec3i(v: [i32; 3]) -> Vec<u8> {
    v.iter().flat_map(|c| c.to_le_bytes()).collect()
}

pub(super) fn vec3d(v: [f64; 3]) -> Vec<u8> {
    v.iter().flat_map(|c| c.to_le_bytes()).collect()
}

/// The grid's metadata and transform.
pub(super) fn put_grid_head(o: &mut dyn Out, g: &GridOut<'_>, grid: &GridSpec) -> std::io::Result<()> {
    let (name, tree, count) = (g.name, g.tree, g.count);
    o.put(&COMPRESS_ACTIVE_MASK.to_le_bytes())?;
    // Bounds of the active voxels: the tiles' boxes, then leaf by leaf: x
    // from the non-zero words, y and z from the bytes and bits of their union.
    let mut bbox: Option<([i32; 3], [i32; 3])> = tree.tile_box;
    for l in &tree.leaves {
        let Some(x0) = l.mask.iter().position(|&w| w != 0) else { continue };
        let x1 = l.mask.iter().rposition(|&w| w != 0).unwrap_or(x0);
        let all = l.mask.iter().fold(0u64, |a, &w| a | w);
        let ys = (0..8u32).filter(|y| (all >> (y * 8)) & 0xff != 0);
        let (y0, y1) = (ys.clone().min().unwrap_or(0), ys.max().unwrap_or(0));
        let zs = (0..8u32).fold(0u64, |a, y| a | ((all >> (y * 8)) & 0xff));
        let (z0, z1) = (zs.trailing_zeros(), 63 - zs.leading_zeros());
        let lo = [l.origin[0] + x0 as u32, l.origin[1] + y0, l.origin[2] + z0].map(|c| c as i32);
        let hi = [l.origin[0] + x1 as u32, l.origin[1] + y1, l.origin[2] + z1].map(|c| c as i32);
        let b = bbox.get_or_insert((lo, hi));
        for a in 0..3 {
            b.0[a] = b.0[a].min(lo[a]);
            b.1[a] = b.1[a].max(hi[a]);
        }
    }
    let o_ = grid.origin();
    let s = grid.voxel_size().0;
    let dims = grid.dims().map(|d| d as i32);
    let mut entries: Vec<(&str, &str, Vec<u8>)> = Vec::new();
    if let Some(class) = g.class {
        entries.push(("class", "string", class.as_bytes().to_vec()));
    }
    if let Some((lo, hi)) = bbox {
        entries.push(("file_bbox_max", "vec3i", vec3i(hi)));
        entries.push(("file_bbox_min", "vec3i", vec3i(lo)));
    }
    entries.push(("file_voxel_count", "int64", (count as i64).to_le_bytes().to_vec()));
    entries.push(("name", "string", name.as_bytes().to_vec()));
    entries.push(("topovox_dims", "vec3i", vec3i(dims)));
    entries.push(("topovox_origin", "vec3d", vec3d(o_.to_array())));
    entries.push(match grid.voxel_size().cube() {
        Some(c) => ("topovox_voxel_size", "double", c.to_le_bytes().to_vec()),
        None => ("topovox_voxel_size", "vec3d", vec3d(s.to_array())),
    });
    o.put(&(entries.len() as u32).to_le_bytes())?;
    for (n, t, v) in &entries {
        put_meta(o, n, t, v)?;
    }
    // OpenVDB's `ScaleTranslateMap::write` order: translation, scale, voxel
    // size, 1/scale, 1/scale², 1/(2·scale); the uniform map is the same.
    put_str(o, if grid.voxel_size().cube().is_some() { "UniformScaleTranslateMap" } else { "ScaleTranslateMap" })?;
    let t = o_ + 0.5 * s;
    for v in [t, s, s, 1.0 / s, 1.0 / (s * s), 0.5 / s] {
        o.put(&vec3d(v.to_array()))?;
    }
    Ok(())
}

/// An internal node's values after its masks: the metadata byte saying no
/// inactive value differs from the background, then one `true` byte per
/// active tile (mask compression stores only active values).
pub(super) fn put_tile_values(o: &mut dyn Out, tiles: &[u64]) -> std::io::Result<()> {
    o.put(&[0])?;
    let n: u32 = tiles.iter().map(|w| w.count_ones()).sum();
    let ones = [1u8; 512];
    let mut left = n as usize;
    while left > 0 {
        let k = left.min(ones.len());
        o.put(&ones[..k])?;
        left -= k;
    }
    Ok(())
}

/// What a tree's nodes hold beyond their topology.
#[derive(Clone, Copy)]
pub(super) enum Buffers<'a> {
    /// A bool grid: tiles are active `true`, leaves' masks are the values.
    Occupancy,
    /// An attribute grid: no tiles, zero background, each leaf's active
    /// values after its mask.
    Attribute(&'a Values<'a>),
    /// A distance field: tiles are inactive `−background` (inside), every
    /// other inactive value `±background` by its sign ([`level_set`]).
    LevelSet(&'a Field),
}

/// An internal node's value mask and values after its child mask: active
/// tiles (`Occupancy`), or for a level set no active tile and a selection
/// mask (metadata 3: a set bit is `+background`, a clear one
/// `−background`), clear where `tiles` are inside.
pub(super) fn put_node_values(o: &mut dyn Out, tiles: &[u64], buffers: Buffers<'_>) -> std::io::Result<()> {
    if let Buffers::LevelSet(_) = buffers {
        put_words(o, &vec![0; tiles.len()])?;
        o.put(&[3])?;
        let outside: Vec<u64> = tiles.iter().map(|w| !w).collect();
        return put_words(o, &outside);
    }
    put_words(o, tiles)?;
    put_tile_values(o, tiles)
}

/// The tree: topology, then buffers.
pub(super) fn put_tree(o: &mut dyn Out, tree: &Tree, buffers: Buffers<'_>) -> std::io::Result<()> {
    o.put(&1i32.to_le_bytes())?; // buffer count
    match buffers {
        Buffers::Occupancy => o.put(&[0])?, // background: false
        Buffers::Attribute(v) => o.put(&[0; 12][..v.size])?,
        Buffers::LevelSet(f) => o.put(&f.background.to_le_bytes())?,
    }
    // Upper nodes: those of lower nodes and of full lower nodes, in order.
    let mut uppers: Vec<(u32, u32, u32)> =
        tree.lowers.iter().map(|l| upper_of(&l.key)).chain(tree.full_lowers.iter().map(upper_of)).collect();
    uppers.sort_unstable();
    uppers.dedup();
    o.put(&0u32.to_le_bytes())?; // tiles
    o.put(&(uppers.len() as u32).to_le_bytes())?;
    let (mut l, mut f) = (0, 0);
    for up in &uppers {
        o.put(&vec3i([up.0, up.1, up.2].map(|c| (c << UPPER) as i32)))?;
        let l_end = l + tree.lowers[l..].iter().take_while(|x| upper_of(&x.key) == *up).count();
        let f_end = f + tree.full_lowers[f..].iter().take_while(|x| upper_of(x) == *up).count();
        let mut child = vec![0u64; 32 * 32 * 32 / 64];
        for x in &tree.lowers[l..l_end] {
            child[x.key.3 as usize / 64] |= 1 << (x.key.3 % 64);
        }
        let mut value = vec![0u64; child.len()];
        for x in &tree.full_lowers[f..f_end] {
            value[x.3 as usize / 64] |= 1 << (x.3 % 64);
        }
        put_words(o, &child)?;
        put_node_values(o, &value, buffers)?;
        for x in &tree.lowers[l..l_end] {
            let mut child = [0u64; 16 * 16 * 16 / 64];
            for leaf in &tree.leaves[x.leaves.clone()] {
                let n = leaf.order().4 as usize;
                child[n / 64] |= 1 << (n % 64);
            }
            put_words(o, &child)?;
            put_node_values(o, &x.tiles[..], buffers)?;
            for leaf in &tree.leaves[x.leaves.clone()] {
                put_words(o, &leaf.mask)?;
            }
        }
        (l, f) = (l_end, f_end);
    }
    match buffers {
        Buffers::Occupancy => put_bool_leaves(o, tree),
        Buffers::Attribute(v) => put_attribute_leaves(o, tree, v),
        Buffers::LevelSet(field) => {
            for leaf in &tree.leaves {
                put_words(o, &leaf.mask)?;
                // Counted from the masks alone: the values are made once, when written.
                o.put_with(level_set::leaf_values_len(field, leaf), &mut |buf| {
                    buf.extend_from_slice(&level_set::leaf_values(field, leaf));
                    Ok(())
                })?;
            }
            Ok(())
        }
    }
}

/// Each leaf's active values after its mask (an attribute grid).
pub(super) fn put_attribute_leaves(o: &mut dyn Out, tree: &Tree, v: &Values<'_>) -> std::io::Result<()> {
    for leaf in &tree.leaves {
        // Value mask, then OpenVDB's compressed values: metadata 0 (every
        // inactive value is the background), the active values in
        // index order (`x·64 + y·8 + z`).
        put_words(o, &leaf.mask)?;
        let active: u32 = leaf.mask.iter().map(|w| w.count_ones()).sum();
        o.put_with(1 + active as usize * v.size, &mut |buf| {
            buf.push(0);
            for (x, &w) in leaf.mask.iter().enumerate() {
                let mut w = w;
                while w != 0 {
                    let b = w.trailing_zeros();
                    w &= w - 1;
                    let p = [leaf.origin[0] + x as u32, leaf.origin[1] + (b >> 3), leaf.origin[2] + (b & 7)];
                    let slot = v.attrs.slot(p[0], p[1], p[2]).ok_or_else(|| {
                        std::io::Error::other(format!("voxel {p:?} is set but has no attributes (voxels and attributes differ)"))
                    })?;
                    (v.put)(slot, buf);
                }
            }
            Ok(())
        })?;
    }
    Ok(())
}

/// Each leaf of a bool grid: value mask (active), origin, values.
pub(super) fn put_bool_leaves(o: &mut dyn Out, tree: &Tree) -> std::io::Result<()> {
    let mut buf = [0u8; 140];
    for leaf in &tree.leaves {
        for (n, w) in leaf.mask.iter().enumerate() {
            buf[8 * n..8 * n + 8].copy_from_slice(&w.to_le_bytes());
            buf[76 + 8 * n..84 + 8 * n].copy_from_slice(&w.to_le_bytes());
        }
        for a in 0..3 {
            buf[64 + 4 * a..68 + 4 * a].copy_from_slice(&(leaf.origin[a] as i32).to_le_bytes());
        }
        o.put(&buf)?;
    }
    Ok(())
}

/// A deterministic UUID-shaped identifier of the contents.
pub(super) fn uuid(grid: &GridSpec, count: u64) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let sizes = grid.voxel_size().recorded().into_iter().map(f64::to_bits);
    for v in grid.dims().iter().map(|&d| d as u64).chain([count]).chain(sizes) {
        h = (h ^ v).wrapping_mul(0x0100_0000_01b3);
    }
    let g = h.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let hex = format!("{h:016x}{g:016x}");
    format!("{}-{}-4{}-8{}-{}", &hex[0..8], &hex[8..12], &hex[13..16], &hex[17..20], &hex[20..32])
}

/// Appends the value of the voxel in an attribute slot, little-endian.
pub(super) type PutValue<'a> = Box<dyn Fn(usize, &mut Vec<u8>) + 'a>;

/// An attribute grid's values: bytes per value, and each voxel's value
/// (by its attribute slot).
pub(super) struct Values<'a> {
    pub(super) attrs: &'a VoxelAttributes,
    pub(super) size: usize,
    pub(super) put: PutValue<'a>,
}

pub(super) fn f32s(buf: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        buf.extend_from_slice(&x.to_le_bytes());
    }
}

/// The attribute grids of `attrs`, as `(name, tree type, values)`: `Cd`
/// (colour, linear RGB), `normal`, `coverage` and `material` (the id as a
/// float, -1 for none; pyopenvdb reads no integer grids).
pub(super) fn attribute_grids(attrs: &VoxelAttributes) -> Vec<(&'static str, &'static str, Values<'_>)> {
    let mut out: Vec<(&'static str, &'static str, Values<'_>)> = Vec::new();
    if let Some(c) = &attrs.colour {
        let put = move |s: usize, b: &mut Vec<u8>| f32s(b, &c[s].map(|v| to_linear(v) as f32));
        out.push((ATTR_COLOUR, VEC3_TYPE, Values { attrs, size: 12, put: Box::new(put) }));
    }
    if let Some(n) = &attrs.normal {
        out.push((ATTR_NORMAL, VEC3_TYPE, Values { attrs, size: 12, put: Box::new(move |s, b| f32s(b, &n[s])) }));
    }
    if let Some(c) = &attrs.coverage {
        out.push((ATTR_COVERAGE, FLOAT_TYPE, Values { attrs, size: 4, put: Box::new(move |s, b| f32s(b, &[c[s]])) }));
    }
    if let Some(m) = &attrs.material {
        let put = move |s: usize, b: &mut Vec<u8>| f32s(b, &[if m[s] == NO_MATERIAL { -1.0 } else { m[s] as f32 }]);
        out.push((ATTR_MATERIAL, FLOAT_TYPE, Values { attrs, size: 4, put: Box::new(put) }));
    }
    out
}

/// Writes `bits` on `grid` as a `.vdb` file: the `voxels` bool grid, then,
/// with `attrs`, one grid per attribute over the same voxels (see the
/// module doc). Grids larger than 2^31 voxels per axis cannot be indexed
/// by OpenVDB's 32-bit coordinates and are refused by the caller's grid
/// limits long before.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec, attrs: Option<&VoxelAttributes>) -> std::io::Result<()> {
    let tree = Tree::of(bits, true);
    let count = bits.count();
    let extra = attrs.map(attribute_grids).unwrap_or_default();
    let value_tree = (!extra.is_empty()).then(|| Tree::of(bits, false));
    let mut grids: Vec<GridOut<'_>> =
        vec![GridOut { name: GRID_NAME, ty: GRID_TYPE, class: None, tree: &tree, buffers: Buffers::Occupancy, count }];
    for (name, ty, v) in &extra {
        let tree = value_tree.as_ref().expect("built when there are attributes");
        grids.push(GridOut { name, ty, class: None, tree, buffers: Buffers::Attribute(v), count });
    }
    write_grids(w, &grids, grid)
}

/// One grid to write: name, tree type, class (metadata `class`), tree,
/// values and active voxel count.
pub(super) struct GridOut<'a> {
    pub(super) name: &'a str,
    pub(super) ty: &'a str,
    pub(super) class: Option<&'a str>,
    pub(super) tree: &'a Tree,
    pub(super) buffers: Buffers<'a>,
    pub(super) count: u64,
}

/// The file: header, then each grid (descriptor, head, tree).
pub(super) fn write_grids(w: &mut dyn Write, grids: &[GridOut<'_>], grid: &GridSpec) -> std::io::Result<()> {
    let count = grids.first().map_or(0, |g| g.count);
    let mut header = Vec::new();
    let mut o = Stream(&mut header);
    let o: &mut dyn Out = &mut o;
    o.put(&MAGIC.to_le_bytes())?;
    o.put(&FILE_VERSION.to_le_bytes())?;
    o.put(&10u32.to_le_bytes())?; // library version the layout follows: 10.0
    o.put(&0u32.to_le_bytes())?;
    o.put(&[1])?; // grid offsets present
    o.put(uuid(grid, count).as_bytes())?;
    o.put(&1u32.to_le_bytes())?; // file metadata: one entry
    put_meta(o, "creator", "string", format!("topovox {}", env!("CARGO_PKG_VERSION")).as_bytes())?;
    o.put(&(grids.len() as i32).to_le_bytes())?;
    w.write_all(&header)?;
    // Each grid: its descriptor with the offsets of its head, its tree and
    // its end (where the next descriptor starts), the head (metadata and
    // transform, small: built in memory), then the tree, streamed after a
    // first pass that only counts its bytes.
    let mut at = header.len() as u64;
    let mut o = Stream(w);
    let o: &mut dyn Out = &mut o;
    for g in grids {
        let mut desc = Count(0);
        put_str(&mut desc, g.name)?;
        put_str(&mut desc, g.ty)?;
        put_str(&mut desc, "")?;
        let mut head = Vec::new();
        put_grid_head(&mut Stream(&mut head), g, grid)?;
        let mut tree_len = Count(0);
        put_tree(&mut tree_len, g.tree, g.buffers)?;
        let grid_pos = at + desc.0 + 24;
        let block_pos = grid_pos + head.len() as u64;
        let end_pos = block_pos + tree_len.0;
        put_str(o, g.name)?;
        put_str(o, g.ty)?;
        put_str(o, "")?;
        for p in [grid_pos, block_pos, end_pos] {
            o.put(&(p as i64).to_le_bytes())?;
        }
        o.put(&head)?;
        put_tree(o, g.tree, g.buffers)?;
        at = end_pos;
    }
    Ok(())
}
