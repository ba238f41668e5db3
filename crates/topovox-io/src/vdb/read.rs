//! Reading untrusted bytes: a bounds-checked cursor, grid descriptors and
//! heads, the topology, values, and the occupancy as dense bits or sparse
//! bricks (tiles as runs of full bricks).

use super::*;

/// A cursor over untrusted bytes: every read is bounds-checked.
pub(super) struct Cur<'a> {
    pub(super) b: &'a [u8],
    pub(super) at: usize,
}

pub(super) fn bad(what: impl Into<String>) -> ErrorKind {
    ErrorKind::malformed("VDB", what.into())
}

impl<'a> Cur<'a> {
    pub(super) fn take(&mut self, n: usize) -> Result<&'a [u8], ErrorKind> {
        if n > self.b.len() - self.at {
            return Err(bad(format!("truncated at byte {} (needs {n} more)", self.at)));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    pub(super) fn u8(&mut self) -> Result<u8, ErrorKind> {
        Ok(self.take(1)?[0])
    }
    pub(super) fn u32(&mut self) -> Result<u32, ErrorKind> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }
    pub(super) fn i32(&mut self) -> Result<i32, ErrorKind> {
        Ok(self.u32()? as i32)
    }
    pub(super) fn i64(&mut self) -> Result<i64, ErrorKind> {
        Ok(i64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    pub(super) fn f64(&mut self) -> Result<f64, ErrorKind> {
        Ok(f64::from_bits(self.i64()? as u64))
    }
    pub(super) fn vec3d(&mut self) -> Result<[f64; 3], ErrorKind> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }
    pub(super) fn coord(&mut self) -> Result<[i32; 3], ErrorKind> {
        Ok([self.i32()?, self.i32()?, self.i32()?])
    }
    pub(super) fn string(&mut self) -> Result<String, ErrorKind> {
        let n = self.u32()? as usize;
        Ok(String::from_utf8_lossy(self.take(n)?).into_owned())
    }
    pub(super) fn words(&mut self, n: usize) -> Result<Vec<u64>, ErrorKind> {
        Ok(self.take(n * 8)?.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes"))).collect())
    }
    pub(super) fn seek(&mut self, pos: i64) -> Result<(), ErrorKind> {
        if pos < 0 || pos as usize > self.b.len() {
            return Err(bad(format!("offset {pos} outside the file")));
        }
        self.at = pos as usize;
        Ok(())
    }
}

/// Metadata entries as (name, type, value bytes).
pub(super) fn read_meta(c: &mut Cur<'_>) -> Result<Vec<(String, String, Vec<u8>)>, ErrorKind> {
    let n = c.u32()?;
    let mut out = Vec::new();
    for _ in 0..n {
        let name = c.string()?;
        let ty = c.string()?;
        let size = c.u32()? as usize;
        out.push((name, ty, c.take(size)?.to_vec()));
    }
    Ok(out)
}

pub(super) fn bit(words: &[u64], n: usize) -> bool {
    words[n / 64] >> (n % 64) & 1 == 1
}

/// A tree as read: active tiles (origin, edge length, value bytes) and
/// leaves (origin, active mask in OpenVDB's layout, active values in index
/// order; none for a bool grid, whose leaves' activity is the occupancy).
#[derive(Default)]
pub(super) struct Found {
    pub(super) tiles: Vec<([i64; 3], i64, [u8; 12])>,
    pub(super) leaves: Vec<[i64; 3]>,
}

/// One node's values as OpenVDB's `readCompressedValues` stores them: the
/// metadata byte, the inactive values and selection mask it announces,
/// then every value or, with active-mask compression, only the active
/// ones. Returns the active values' bytes in index order.
pub(super) fn read_values(c: &mut Cur<'_>, active: &[u64], n: usize, mask_compressed: bool, vs: usize) -> Result<Vec<u8>, ErrorKind> {
    let meta = c.u8()?;
    match meta {
        // 0: inactive values are the background, 1: its negative, 3: a
        // mask selects between the two, 6: every value stored.
        0 | 1 | 3 | 6 => {}
        2 | 4 => {
            c.take(vs)?; // one inactive value
        }
        5 => {
            c.take(2 * vs)?; // two inactive values
        }
        m => return Err(bad(format!("unknown node compression metadata {m}"))),
    }
    if matches!(meta, 3..=5) {
        c.take(n / 8)?; // selection mask
    }
    let on: usize = active.iter().map(|w| w.count_ones() as usize).sum();
    if mask_compressed && meta != 6 {
        return Ok(c.take(on * vs)?.to_vec());
    }
    let all = c.take(n * vs)?;
    let mut out = Vec::with_capacity(on * vs);
    for idx in (0..n).filter(|&i| bit(active, i)) {
        out.extend_from_slice(&all[idx * vs..(idx + 1) * vs]);
    }
    Ok(out)
}

/// How a distance field's values are read as voxels: its background, and
/// which values are inside (see [`read_level_set`]).
#[derive(Clone, Copy)]
pub(super) struct Inside<'a> {
    pub(super) background: [u8; 4],
    pub(super) test: &'a dyn Fn(f32) -> bool,
}

/// An internal node's topology: masks, compressed tile values, children.
/// With `inside`, its tiles are those whose value (active or not) is
/// inside, not the active ones.
pub(super) fn read_internal(
    c: &mut Cur<'_>,
    origin: [i64; 3],
    (log2, child_log2): (u32, u32),
    mask_compressed: bool,
    vs: usize,
    found: &mut Found,
    inside: Option<Inside<'_>>,
) -> Result<(), ErrorKind> {
    let dim = log2 - child_log2;
    let n = 1usize << (3 * dim);
    let child = c.words(n / 64)?;
    let value = c.words(n / 64)?;
    let offset = |idx: usize| -> [i64; 3] {
        let off = [(idx >> (2 * dim)) as i64, ((idx >> dim) & ((1 << dim) - 1)) as i64, (idx & ((1 << dim) - 1)) as i64];
        std::array::from_fn(|a| origin[a] + (off[a] << child_log2))
    };
    if let Some(ins) = inside {
        let all = read_all_values(c, &value, n, mask_compressed, ins.background)?;
        for idx in (0..n).filter(|&i| !bit(&child, i) && (ins.test)(all[i])) {
            found.tiles.push((offset(idx), 1 << child_log2, [1; 12]));
        }
    } else {
        let vals = read_values(c, &value, n, mask_compressed, vs)?;
        for (v, idx) in (0..n).filter(|&i| bit(&value, i)).enumerate() {
            if !bit(&child, idx) {
                let mut val = [0u8; 12];
                val[..vs].copy_from_slice(&vals[v * vs..(v + 1) * vs]);
                found.tiles.push((offset(idx), 1 << child_log2, val));
            }
        }
    }
    for idx in (0..n).filter(|&i| bit(&child, i)) {
        let o = offset(idx);
        if child_log2 == LEAF {
            c.take(64)?; // the leaf's value mask, read again with its buffer
            found.leaves.push(o);
        } else {
            read_internal(c, o, (child_log2, LEAF), mask_compressed, vs, found, inside)?;
        }
    }
    Ok(())
}

/// Every one of a float node's `n` values as OpenVDB's
/// `readCompressedValues` restores them: the active ones as stored, the
/// inactive ones by the metadata byte (0: the background, 1: its negative,
/// 2/4/5: values stored once, 3–5: a selection mask choosing between two
/// of them, 6: every value stored).
pub(super) fn read_all_values(
    c: &mut Cur<'_>,
    active: &[u64],
    n: usize,
    mask_compressed: bool,
    background: [u8; 4],
) -> Result<Vec<f32>, ErrorKind> {
    let bg = f32::from_le_bytes(background);
    let f = |b: &[u8]| f32::from_le_bytes(b.try_into().expect("4 bytes"));
    let meta = c.u8()?;
    if meta > 6 {
        return Err(bad(format!("unknown node compression metadata {meta}")));
    }
    let mut inactive = [if meta == 0 { bg } else { -bg }, bg];
    if matches!(meta, 2 | 4 | 5) {
        inactive[0] = f(c.take(4)?);
    }
    if meta == 5 {
        inactive[1] = f(c.take(4)?);
    }
    let selection = if matches!(meta, 3..=5) { Some(c.take(n / 8)?) } else { None };
    let chosen = |i: usize| inactive[selection.is_some_and(|m| m[i / 8] >> (i % 8) & 1 == 1) as usize];
    if mask_compressed && meta != 6 {
        let on: usize = active.iter().map(|w| w.count_ones() as usize).sum();
        let mut stored = c.take(on * 4)?.chunks_exact(4);
        return Ok((0..n).map(|i| if bit(active, i) { stored.next().map_or(bg, f) } else { chosen(i) }).collect());
    }
    Ok(c.take(n * 4)?.chunks_exact(4).map(f).collect())
}

/// A grid's descriptor: name, tree type, where its head starts.
pub(super) struct Descriptor {
    pub(super) name: String,
    pub(super) ty: String,
    pub(super) pos: i64,
}

/// A file's grid descriptors, after its header.
pub(super) fn descriptors(bytes: &[u8]) -> Result<Vec<Descriptor>, ErrorKind> {
    let mut c = Cur { b: bytes, at: 0 };
    if c.i64().ok() != Some(MAGIC) {
        return Err(bad("not an OpenVDB file (bad magic number)"));
    }
    let version = c.u32()?;
    if version < MIN_VERSION {
        return Err(bad(format!("file format {version} is older than {MIN_VERSION}, the oldest topovox reads")));
    }
    c.u32()?;
    c.u32()?;
    let has_offsets = c.u8()? != 0;
    c.take(36)?; // UUID
    read_meta(&mut c)?;
    let grids = c.i32()?;
    if !has_offsets {
        return Err(bad("streamed VDB files (without grid offsets) are not supported"));
    }
    let mut found = Vec::new();
    for _ in 0..grids.max(0) {
        let name = c.string()?;
        let ty = c.string()?;
        if version >= 223 {
            c.string()?;
        }
        let (pos, _block, end) = (c.i64()?, c.i64()?, c.i64()?);
        // Grids follow one another: an end before this descriptor would
        // read the same grids again, billions of times.
        if end <= c.at as i64 {
            return Err(bad(format!("grid '{name}' ends at byte {end}, before its own descriptor")));
        }
        found.push(Descriptor { name, ty, pos });
        c.seek(end)?;
    }
    Ok(found)
}

pub(super) fn in_grid(name: &str, e: ErrorKind) -> ErrorKind {
    match e {
        ErrorKind::Malformed { format, detail } => ErrorKind::Malformed { format, detail: format!("grid '{name}': {detail}") },
        e => e,
    }
}

/// The voxels of a file: its first bool grid; without one, its first
/// float grid that is a level set or topovox's distance field (`surface`),
/// read as the voxels inside (negative; unsigned: within half a voxel
/// diagonal of the surface).
pub(super) fn occupancy(bytes: &[u8], found: &[Descriptor]) -> Result<Occupancy, ErrorKind> {
    let bool_grid = found.iter().find(|d| d.ty == GRID_TYPE);
    let distance = || {
        found.iter().filter(|d| d.ty == FLOAT_TYPE).find(|d| {
            let mut c = Cur { b: bytes, at: 0 };
            d.name == level_set::LEVEL_SET_NAME
                || (c.seek(d.pos).is_ok() && read_head(&mut c).is_ok_and(|h| h.meta.iter().any(|m| m.0 == "class" && m.2 == b"level set")))
        })
    };
    let Some((d, is_distance)) = bool_grid.map(|d| (d, false)).or_else(|| distance().map(|d| (d, true))) else {
        let types: Vec<String> = found.iter().map(|d| format!("{} ({})", d.name, d.ty)).collect();
        return Err(bad(if types.is_empty() {
            "no grids".to_string()
        } else {
            format!("no bool grid or level set (topovox reads {GRID_TYPE}, and {FLOAT_TYPE} level sets); grids: {}", types.join(", "))
        }));
    };
    let mut c = Cur { b: bytes, at: 0 };
    c.seek(d.pos)?;
    read_grid(&mut c, is_distance).map_err(|e| in_grid(&d.name, e))
}

/// The attribute grids topovox reads: name and tree type.
pub(super) const ATTRIBUTE_GRIDS: [(&str, &str); 4] =
    [(ATTR_COLOUR, VEC3_TYPE), (ATTR_NORMAL, VEC3_TYPE), (ATTR_COVERAGE, FLOAT_TYPE), (ATTR_MATERIAL, FLOAT_TYPE)];

/// A `.vdb` file's voxels without a dense grid: its first bool grid as
/// sparse bricks (active tiles as runs of full bricks), the placement,
/// and with `attributes` the attribute grids of its set voxels (memory:
/// about 32 bytes per voxel); otherwise whether any were left unread.
pub fn read_sparse(bytes: &[u8], attributes: bool) -> Result<SparseVoxels, ErrorKind> {
    let found = descriptors(bytes)?;
    let occ = occupancy(bytes, &found)?;
    let has = found.iter().any(|d| ATTRIBUTE_GRIDS.contains(&(d.name.as_str(), d.ty.as_str())));
    let (bits, placement, offset) = (occ.sparse()?, occ.placement, occ.offset);
    drop(occ);
    let attrs = if attributes && has { read_attributes(bytes, &found, offset, &bits)? } else { None };
    Ok(SparseVoxels { bits, placement, attributes_left: has && attrs.is_none(), attributes: attrs })
}

/// Parses a `.vdb` file: its first bool grid's active voxels and, when
/// grids named as topovox writes them are present (`Cd`, `normal`,
/// `coverage`, `material`), those attributes of each voxel.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let found = descriptors(bytes)?;
    let occ = occupancy(bytes, &found)?;
    let mut loaded = LoadedVoxels { bits: occ.dense()?, placement: occ.placement, attributes: None };
    let offset = occ.offset;
    drop(occ);
    loaded.attributes = read_attributes(bytes, &found, offset, &loaded.bits)?;
    Ok(loaded)
}

/// The attribute grids topovox writes (`Cd`, `normal`, `coverage`,
/// `material`) at the set voxels of `voxels` (any storage; index
/// coordinates shifted by `offset`), or `None` when the file has none.
pub(super) fn read_attributes(
    bytes: &[u8],
    found: &[Descriptor],
    offset: [i64; 3],
    voxels: &dyn VoxelSource,
) -> Result<Option<VoxelAttributes>, ErrorKind> {
    let wanted = ATTRIBUTE_GRIDS;
    if !found.iter().any(|d| wanted.contains(&(d.name.as_str(), d.ty.as_str()))) {
        return Ok(None);
    }
    let mut c = Cur { b: bytes, at: 0 };
    let mut attrs = VoxelAttributes { dims: voxels.dims(), keys: VoxelAttributes::keys_of(voxels), ..Default::default() };
    for (name, ty) in wanted {
        let Some(d) = found.iter().find(|d| d.name == name && d.ty == ty) else { continue };
        c.seek(d.pos)?;
        let values = read_values_grid(&mut c, if ty == VEC3_TYPE { 12 } else { 4 }).map_err(|e| in_grid(name, e))?;
        let mut read = values.reader();
        let mut at = |key: u64| {
            let v = attrs.voxel(key);
            read(std::array::from_fn(|a| v[a] as i64 + offset[a]))
        };
        let f = |b: &[u8], n: usize| f32::from_le_bytes(b[4 * n..4 * n + 4].try_into().expect("4 bytes"));
        // One lookup per voxel, its three components read from it.
        match name {
            ATTR_COLOUR => {
                attrs.colour = Some(
                    attrs
                        .keys
                        .iter()
                        .map(|&k| {
                            let v = at(k);
                            std::array::from_fn(|n| from_linear(f(&v, n) as f64))
                        })
                        .collect(),
                )
            }
            ATTR_NORMAL => {
                attrs.normal = Some(
                    attrs
                        .keys
                        .iter()
                        .map(|&k| {
                            let v = at(k);
                            std::array::from_fn(|n| f(&v, n))
                        })
                        .collect(),
                )
            }
            ATTR_COVERAGE => attrs.coverage = Some(attrs.keys.iter().map(|&k| f(&at(k), 0)).collect()),
            _ => {
                let id = |v: f32| if v >= 0.0 && v.fract() == 0.0 && v < NO_MATERIAL as f32 { v as u32 } else { NO_MATERIAL };
                attrs.material = Some(attrs.keys.iter().map(|&k| id(f(&at(k), 0))).collect());
            }
        }
    }
    Ok(Some(attrs))
}

/// The grid head up to its tree: compression flags, metadata, transform.
pub(super) struct Head {
    pub(super) mask_compressed: bool,
    pub(super) meta: Vec<(String, String, Vec<u8>)>,
    pub(super) translation: [f64; 3],
    pub(super) scale: [f64; 3],
}

pub(super) fn read_head(c: &mut Cur<'_>) -> Result<Head, ErrorKind> {
    let compression = c.u32()?;
    if compression & (COMPRESS_ZIP | COMPRESS_BLOSC) != 0 {
        return Err(bad("zip/blosc-compressed grids are not supported (topovox writes uncompressed VDB; re-save without compression)"));
    }
    let mask_compressed = compression & COMPRESS_ACTIVE_MASK != 0;
    let meta = read_meta(c)?;
    let map = c.string()?;
    let (translation, scale) = match map.as_str() {
        "UniformScaleTranslateMap" | "ScaleTranslateMap" => {
            let t = c.vec3d()?;
            let s = c.vec3d()?;
            for _ in 0..4 {
                c.vec3d()?;
            }
            (t, s)
        }
        "UniformScaleMap" | "ScaleMap" => {
            let s = c.vec3d()?;
            for _ in 0..4 {
                c.vec3d()?;
            }
            ([0.0; 3], s)
        }
        "TranslationMap" => (c.vec3d()?, [1.0; 3]),
        m => return Err(bad(format!("transform {m} is not supported (topovox reads scale and translation maps)"))),
    };
    Ok(Head { mask_compressed, meta, translation, scale })
}

/// A tree's root and internal nodes, values `vs` bytes each.
pub(super) fn read_topology(
    c: &mut Cur<'_>,
    mask_compressed: bool,
    vs: usize,
    test: Option<&dyn Fn(f32) -> bool>,
) -> Result<(Found, [u8; 12]), ErrorKind> {
    if c.i32()? != 1 {
        return Err(bad("multi-buffer trees are not supported"));
    }
    let mut background = [0u8; 12];
    background[..vs].copy_from_slice(c.take(vs)?);
    let inside = test.map(|test| Inside { background: background[..4].try_into().expect("4 bytes"), test });
    let (ntiles, nchildren) = (c.u32()? as usize, c.u32()? as usize);
    // Each tile takes 13 + vs bytes, each child at least 12 + 2·4096 + 1.
    if ntiles.saturating_mul(13 + vs).saturating_add(nchildren.saturating_mul(8205)) > c.b.len() - c.at {
        return Err(bad(format!("root claims {ntiles} tiles and {nchildren} children, more than the file holds")));
    }
    let mut found = Found::default();
    for _ in 0..ntiles {
        let o = c.coord()?;
        let mut val = [0u8; 12];
        val[..vs].copy_from_slice(c.take(vs)?);
        let active = c.u8()? != 0;
        // A distance field's root tile counts when inside, active or not.
        let counts = match inside {
            Some(ins) => (ins.test)(f32::from_le_bytes(val[..4].try_into().expect("4 bytes"))),
            None => active,
        };
        if counts {
            found.tiles.push((o.map(|v| v as i64), 1 << UPPER, val));
        }
    }
    for _ in 0..nchildren {
        let o = c.coord()?;
        read_internal(c, o.map(|v| v as i64), (UPPER, LOWER), mask_compressed, vs, &mut found, inside)?;
    }
    Ok((found, background))
}

/// An attribute grid's active values, looked up by index coordinate.
pub(super) struct GridValues {
    pub(super) vs: usize,
    /// Leaf origin → (active mask, active values).
    pub(super) leaves: std::collections::HashMap<[i64; 3], (Vec<u64>, Vec<u8>)>,
    /// (Tile origin, edge) → value.
    pub(super) tiles: std::collections::HashMap<([i64; 3], i64), [u8; 12]>,
}

/// Where one leaf-sized block of an attribute grid takes its values.
#[derive(Clone, Copy)]
pub(super) enum Block<'a> {
    Leaf(&'a [u64], &'a [u8]),
    Constant([u8; 12]),
}

impl GridValues {
    /// The leaf-sized block at `origin` (a multiple of 8): its leaf, else
    /// the active tile holding it, else zero (the background topovox writes).
    pub(super) fn block(&self, origin: [i64; 3]) -> Block<'_> {
        if let Some((mask, vals)) = self.leaves.get(&origin) {
            return Block::Leaf(mask, vals);
        }
        for edge in [1i64 << LEAF, 1 << LOWER, 1 << UPPER] {
            if let Some(v) = self.tiles.get(&(origin.map(|c| c & !(edge - 1)), edge)) {
                return Block::Constant(*v);
            }
        }
        Block::Constant([0; 12])
    }

    /// A lookup of values by index coordinate that finds each block once
    /// per run of voxels in it (voxels come in row order, so a leaf's
    /// eight voxels along x cost one map lookup, not eight).
    pub(super) fn reader(&self) -> impl FnMut([i64; 3]) -> [u8; 12] + '_ {
        let mut last: Option<([i64; 3], Block<'_>)> = None;
        move |p| {
            let origin = p.map(|c| c & !7);
            let block = match last {
                Some((o, b)) if o == origin => b,
                _ => {
                    let b = self.block(origin);
                    last = Some((origin, b));
                    b
                }
            };
            match block {
                Block::Constant(v) => v,
                Block::Leaf(mask, vals) => {
                    let mut out = [0u8; 12];
                    let n = ((p[0] & 7) * 64 + (p[1] & 7) * 8 + (p[2] & 7)) as usize;
                    if bit(mask, n) {
                        let below = mask[..n / 64].iter().map(|w| w.count_ones() as usize).sum::<usize>()
                            + (mask[n / 64] & ((1u64 << (n % 64)) - 1)).count_ones() as usize;
                        out[..self.vs].copy_from_slice(&vals[below * self.vs..(below + 1) * self.vs]);
                    }
                    out
                }
            }
        }
    }
}

pub(super) fn read_values_grid(c: &mut Cur<'_>, vs: usize) -> Result<GridValues, ErrorKind> {
    let head = read_head(c)?;
    if head.meta.iter().any(|m| m.0 == "is_saved_as_half_float" && m.2.first().is_some_and(|&b| b != 0)) {
        return Err(bad("half-float grids are not supported (topovox writes 32-bit floats)"));
    }
    let (found, _) = read_topology(c, head.mask_compressed, vs, None)?;
    let mut leaves = std::collections::HashMap::with_capacity(found.leaves.len());
    for o in &found.leaves {
        let active = c.words(8)?;
        let vals = read_values(c, &active, 512, head.mask_compressed, vs)?;
        leaves.insert(*o, (active, vals));
    }
    let tiles = found.tiles.iter().map(|(o, e, v)| ((*o, *e), *v)).collect();
    Ok(GridValues { vs, leaves, tiles })
}

/// The bool grid as read, before it becomes voxels: leaves (origin,
/// active mask in OpenVDB's layout), active `true` tiles (origin, edge),
/// the index coordinate of voxel (0, 0, 0), the grid's dims and placement.
pub(super) struct Occupancy {
    pub(super) leaves: Vec<([i64; 3], [u64; 8])>,
    pub(super) tiles: Vec<([i64; 3], i64)>,
    pub(super) offset: [i64; 3],
    pub(super) dims: [u32; 3],
    pub(super) placement: Option<(DVec3, DVec3)>,
}

impl Occupancy {
    /// Voxel coordinates of index coordinate `p`, which must be in the grid.
    pub(super) fn inside(&self, p: [i64; 3]) -> Result<[u32; 3], ErrorKind> {
        let q: [i64; 3] = std::array::from_fn(|a| p[a] - self.offset[a]);
        if (0..3).any(|a| q[a] < 0 || q[a] >= self.dims[a] as i64) {
            return Err(bad(format!("active voxel {p:?} outside the recorded grid {:?}", self.dims)));
        }
        Ok(q.map(|c| c as u32))
    }

    /// Calls `f` with every active voxel of the leaves (voxel coordinates).
    pub(super) fn leaf_voxels(&self, mut f: impl FnMut([u32; 3])) -> Result<(), ErrorKind> {
        for (o, m) in &self.leaves {
            for (x, &w) in m.iter().enumerate() {
                let mut w = w;
                while w != 0 {
                    let b = w.trailing_zeros() as i64;
                    w &= w - 1;
                    f(self.inside([o[0] + x as i64, o[1] + (b >> 3), o[2] + (b & 7)])?);
                }
            }
        }
        Ok(())
    }

    /// The voxels in a dense grid (active tiles filled a row of words at a time).
    pub(super) fn dense(&self) -> Result<topovox::DenseBits, ErrorKind> {
        // First: a grid that cannot be dense says so (`TooLarge`; the sparse
        // reader takes such files).
        let mut bits = crate::dense_grid(self.dims)?;
        // Tiles of one tree never overlap, so together they cover at most
        // the grid, which fits (checked above): any number of voxels a
        // solid's interior takes reads back. More means overlapping tiles,
        // which a 200-byte file can claim by the thousand (each would be
        // filled again): refused.
        let grid_voxels = self.dims.iter().map(|&d| d as i64).product::<i64>();
        let tile_voxels: i64 = self.tiles.iter().fold(0i64, |n, t| n.saturating_add(t.1.saturating_mul(t.1).saturating_mul(t.1)));
        if tile_voxels > grid_voxels {
            return Err(bad(format!("active tiles cover {tile_voxels} voxels, more than the grid's {grid_voxels}: they overlap")));
        }
        let mut tiles = Vec::with_capacity(self.tiles.len());
        for (o, e) in &self.tiles {
            // A tile is inside the grid when its two corners are.
            tiles.push((self.inside(*o)?, self.inside(o.map(|c| c + e - 1))?));
        }
        self.leaf_voxels(|q| bits.set(q[0], q[1], q[2]))?;
        for (lo, hi) in tiles {
            bits.fill_box(lo, hi);
        }
        Ok(bits)
    }

    /// The voxels as sparse bricks: leaves become bricks, active tiles runs
    /// of full bricks (never voxels), so memory follows the file, not the
    /// grid. Needs the grid to start on a brick (topovox's files do).
    pub(super) fn sparse(&self) -> Result<SparseBricks, ErrorKind> {
        if self.offset.iter().any(|o| o % 8 != 0) {
            return Err(ErrorKind::Unsupported(format!(
                "this grid's voxels start at index {:?}, not on an 8-voxel brick, so it is read only into a dense grid",
                self.offset
            )));
        }
        if self.dims.iter().any(|&d| d > SparseBricks::MAX_DIM) {
            return Err(bad(format!("grid {:?} beyond {} voxels per axis", self.dims, SparseBricks::MAX_DIM)));
        }
        // The offset is a multiple of 8, so a leaf's voxels, visited
        // together, all fall in one brick.
        let mut bricks: Vec<([u32; 3], Brick)> = Vec::with_capacity(self.leaves.len());
        self.leaf_voxels(|q| {
            let b = q.map(|c| c / 8);
            if bricks.last().is_none_or(|l| l.0 != b) {
                bricks.push((b, [0; 8]));
            }
            set_in_brick(&mut bricks.last_mut().expect("pushed above").1, q[0], q[1], q[2]);
        })?;
        let mut runs: Vec<([u32; 3], u32)> = Vec::new();
        for (o, e) in &self.tiles {
            let (lo, _) = (self.inside(*o)?, self.inside(o.map(|c| c + e - 1))?);
            let n = (*e / 8) as u32;
            if runs.len() as u64 + (n as u64) * (n as u64) > MAX_SPARSE_RUNS {
                return Err(bad(format!("active tiles make more than {MAX_SPARSE_RUNS} brick rows")));
            }
            let b = lo.map(|c| c / 8);
            for bk in b[2]..b[2] + n {
                for bj in b[1]..b[1] + n {
                    runs.push(([b[0], bj, bk], n));
                }
            }
        }
        Ok(SparseBricks::from_parts(self.dims, bricks, runs))
    }
}

/// Most rows of full bricks the sparse reader makes from active tiles (16
/// bytes each: 1 GiB; a 4096³ tile is 262 144 rows).
pub(super) const MAX_SPARSE_RUNS: u64 = 1 << 26;

/// Tiles and leaves (OpenVDB's mask layout) as a grid's voxels.
pub(super) type TreeVoxels = (Vec<([i64; 3], i64)>, Vec<([i64; 3], [u64; 8])>);

/// A bool tree's active tiles and leaves.
pub(super) fn read_bool_tree(c: &mut Cur<'_>, mask_compressed: bool) -> Result<TreeVoxels, ErrorKind> {
    let (found, _) = read_topology(c, mask_compressed, 1, None)?;
    let tiles: Vec<([i64; 3], i64)> = found.tiles.iter().filter(|t| t.2[0] != 0).map(|t| (t.0, t.1)).collect();
    // Masks inline: a heap vector per leaf would more than double the
    // memory of a large file's tree.
    let mut leaves: Vec<([i64; 3], [u64; 8])> = Vec::with_capacity(found.leaves.len());
    for expect in &found.leaves {
        let active = c.words(8)?;
        let o = c.coord()?.map(|v| v as i64);
        if o != *expect {
            return Err(bad(format!("leaf at {o:?} where the topology has {expect:?}")));
        }
        c.words(8)?; // values: occupancy is activity
        leaves.push((o, active.try_into().expect("8 words")));
    }
    Ok((tiles, leaves))
}

/// A float tree (a distance field) as the voxels whose values, active or
/// not, pass `test`: tiles wholly inside, and per leaf a mask of them.
pub(super) fn read_level_set(c: &mut Cur<'_>, mask_compressed: bool, test: &dyn Fn(f32) -> bool) -> Result<TreeVoxels, ErrorKind> {
    let (found, background) = read_topology(c, mask_compressed, 4, Some(test))?;
    let tiles = found.tiles.iter().map(|t| (t.0, t.1)).collect();
    let mut leaves = Vec::with_capacity(found.leaves.len());
    for o in &found.leaves {
        let active = c.words(8)?;
        let values = read_all_values(c, &active, 512, mask_compressed, background[..4].try_into().expect("4 bytes"))?;
        let mut mask = [0u64; 8];
        for (n, _) in values.iter().enumerate().filter(|(_, &v)| test(v)) {
            mask[n / 64] |= 1 << (n % 64);
        }
        leaves.push((*o, mask));
    }
    Ok((tiles, leaves))
}

/// The bool grid at the cursor.
pub(super) fn read_grid(c: &mut Cur<'_>, distance: bool) -> Result<Occupancy, ErrorKind> {
    let Head { mask_compressed, meta, translation, scale } = read_head(c)?;
    let find = |n: &str| meta.iter().find(|m| m.0 == n).map(|m| m.2.clone());
    // Our own keys (`topovox_dims`, …), or as written before the rename.
    let get = |n: &str| {
        find(n).or_else(|| n.strip_prefix("topovox_").and_then(|rest| find(&format!("{}{rest}", crate::former_name::VDB_META_PREFIX))))
    };
    let (tiles, leaves) = if distance {
        // A level set's inside: its negative values; an unsigned field's
        // voxels within half a voxel diagonal of the surface.
        let level_set = find("class").is_some_and(|c| c == b"level set");
        let near = crate::half_diagonal(DVec3::from(scale));
        let test = move |v: f32| if level_set { v < 0.0 } else { (v as f64) <= near };
        read_level_set(c, mask_compressed, &test)?
    } else {
        read_bool_tree(c, mask_compressed)?
    };
    // The index box of the active voxels.
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    let mut grow = |p: [i64; 3], q: [i64; 3]| {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(q[a]);
        }
    };
    for (o, e) in &tiles {
        grow(*o, o.map(|c| c + e - 1));
    }
    for (o, m) in &leaves {
        if m.iter().any(|&w| w != 0) {
            grow(*o, o.map(|c| c + 7));
        }
    }
    let dims_meta = get("topovox_dims").filter(|v| v.len() == 12).map(|v| {
        let d: [i32; 3] = std::array::from_fn(|a| i32::from_le_bytes(v[4 * a..4 * a + 4].try_into().expect("4 bytes")));
        d
    });
    let (offset, dims) = match dims_meta {
        Some(d) if d.iter().all(|&x| x > 0) => ([0i64; 3], d.map(|x| x as u32)),
        _ if lo[0] == i64::MAX => ([0; 3], [1, 1, 1]),
        _ => (lo, std::array::from_fn(|a| u32::try_from(hi[a] - lo[a] + 1).unwrap_or(u32::MAX))),
    };
    let vec3d = |v: Vec<u8>| {
        DVec3::from(std::array::from_fn::<f64, 3, _>(|a| f64::from_le_bytes(v[8 * a..8 * a + 8].try_into().expect("8 bytes"))))
    };
    let origin_meta = get("topovox_origin").filter(|v| v.len() == 24).map(vec3d);
    // A `double` for cubes, a `vec3d` for boxes.
    let size_meta = get("topovox_voxel_size").and_then(|v| match v.len() {
        8 => Some(DVec3::splat(f64::from_le_bytes(v[..8].try_into().expect("8 bytes")))),
        24 => Some(vec3d(v)),
        _ => None,
    });
    let scale = DVec3::from(scale);
    let placement = match (origin_meta, size_meta) {
        (Some(o), Some(s)) if dims_meta.is_some() => Some((o, s)),
        _ if scale.is_finite() && scale.min_element() > 0.0 => {
            Some((DVec3::from(translation) + DVec3::new(offset[0] as f64, offset[1] as f64, offset[2] as f64) * scale - 0.5 * scale, scale))
        }
        _ => None,
    };
    Ok(Occupancy { leaves, tiles, offset, dims, placement })
}
