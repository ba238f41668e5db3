//! MagicaVoxel `.vox`, through the `dot_vox` crate.
//!
//! MagicaVoxel is z-up: the grid is first rotated so the data's up axis
//! (`--up`, default y) points up there ([`crate::orient`]).
//!
//! A grid of at most 256 voxels on a side is one model and nothing else
//! (no scene graph: the simplest files, which every reader takes).
//! Larger grids are cut into 256³ blocks; block `(bx, by, bz)` becomes one
//! model, placed in the scene graph (root transform → group → one
//! transform + shape per model). A model's world minimum corner is its
//! transform's translation `_t` minus `floor(size / 2)` (MagicaVoxel pivots
//! models on their centre), so `_t` is set to `256·(bx,by,bz) +
//! floor(size/2)` and the whole grid opens in MagicaVoxel in one piece. The
//! root transform records the up axis (`_topovox_up`), so reading needs no
//! `--up`; single models are read with the `up` given.
//!
//! Colours: with voxel colours, the palette is at most 255 colours of the
//! voxels themselves ([`topovox::attributes::quantize`]: exact when there
//! are no more, else median cut + k-means in Oklab), each voxel taking its
//! nearest entry (or, with dithering, error diffusion across neighbours).
//! Without colours every voxel uses palette entry 1 (a light grey).

use std::collections::BTreeMap;
use std::io::Write;

use dot_vox::{Color, Dict, DotVoxData, Frame, Layer, Model, SceneNode, ShapeModel, Size, Voxel};
use topovox::attributes::{quantize, VoxelAttributes};
use topovox::VoxelSource;

use crate::error::ErrorKind;
use crate::orient::{Orientation, Up};
use crate::LoadedVoxels;

const BLOCK: u32 = 256;

/// Writes `bits` as a `.vox` file, coloured by `attrs` when it has colours,
/// rotated so `up` points up.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, attrs: Option<&VoxelAttributes>, dither: bool, up: Up) -> std::io::Result<()> {
    let orient = Orientation::magicavoxel(up);
    let src_dims = bits.dims();
    let dims = orient.dims(src_dims);
    let coloured = attrs.and_then(|a| a.colour.as_ref().map(|c| (a, c)));
    let (palette_rgb, index) = match coloured {
        Some((a, colours)) => {
            let p = quantize::palette(colours, 255);
            let idx = if dither { quantize::dither(a, colours, &p) } else { quantize::map_to_palette(colours, &p) };
            (p, Some((a, idx)))
        }
        None => (vec![[200, 205, 215]], None),
    };
    let palette_index = |i: u32, j: u32, k: u32| -> u8 {
        match &index {
            Some((a, idx)) => a.slot(i, j, k).map(|s| idx[s]).unwrap_or(0),
            None => 0,
        }
    };
    let mut blocks: BTreeMap<[u32; 3], Vec<Voxel>> = BTreeMap::new();
    bits.for_each_set(&mut |i, j, k| {
        let [x, y, z] = orient.apply([i, j, k], src_dims);
        blocks.entry([x / BLOCK, y / BLOCK, z / BLOCK]).or_default().push(Voxel {
            x: (x % BLOCK) as u8,
            y: (y % BLOCK) as u8,
            z: (z % BLOCK) as u8,
            i: palette_index(i, j, k),
        });
    });
    if blocks.is_empty() {
        blocks.insert([0, 0, 0], Vec::new());
    }
    let single = blocks.len() == 1 && dims.iter().all(|&d| d <= BLOCK);
    let mut models = Vec::with_capacity(blocks.len());
    let root = Dict::from_iter([("_topovox_up".to_string(), up.to_string())]);
    let mut scenes = vec![
        SceneNode::Transform { attributes: root, frames: vec![Frame::new(Dict::new())], child: 1, layer_id: u32::MAX },
        SceneNode::Group { attributes: Dict::new(), children: Vec::new() },
    ];
    let mut children = Vec::new();
    for (b, voxels) in blocks {
        let size: [u32; 3] = std::array::from_fn(|a| (dims[a] - b[a] * BLOCK).min(BLOCK));
        let t: [i64; 3] = std::array::from_fn(|a| (b[a] * BLOCK + size[a] / 2) as i64);
        let model_id = models.len() as u32;
        models.push(Model { size: Size { x: size[0], y: size[1], z: size[2] }, voxels });
        let tr = scenes.len() as u32;
        children.push(tr);
        let mut attrs = Dict::new();
        attrs.insert("_t".to_string(), format!("{} {} {}", t[0], t[1], t[2]));
        scenes.push(SceneNode::Transform { attributes: Dict::new(), frames: vec![Frame::new(attrs)], child: tr + 1, layer_id: 0 });
        scenes.push(SceneNode::Shape { attributes: Dict::new(), models: vec![ShapeModel { model_id, attributes: Dict::new() }] });
    }
    if let SceneNode::Group { children: c, .. } = &mut scenes[1] {
        *c = children;
    }
    let mut palette = vec![Color { r: 75, g: 75, b: 75, a: 255 }; 256];
    for (p, c) in palette.iter_mut().zip(&palette_rgb) {
        *p = Color { r: c[0], g: c[1], b: c[2], a: 255 };
    }
    let (scenes, layers) = if single {
        (Vec::new(), Vec::new())
    } else {
        (scenes, vec![Layer { attributes: Dict::from_iter([("_name".to_string(), "topovox".to_string())]) }])
    };
    let data = DotVoxData { version: 150, index_map: Vec::new(), models, palette, materials: Vec::new(), scenes, layers };
    data.write_vox(&mut &mut *w)
}

/// Reads a `.vox` file: every model placed by the translations of the
/// transforms above it (rotations are not supported), shifted so the
/// smallest model corner is voxel `(0,0,0)`, then rotated back from
/// MagicaVoxel's z-up to the data's axes: by the up axis the file records
/// (topovox's multi-model files), else by `up`.
pub fn read(bytes: &[u8], up: Up) -> Result<LoadedVoxels, ErrorKind> {
    let data = dot_vox::load_bytes(bytes).map_err(|e| ErrorKind::malformed("vox", e))?;
    let mut placed: Vec<(u32, [i64; 3])> = Vec::new();
    if data.scenes.is_empty() {
        for m in 0..data.models.len() {
            placed.push((m as u32, [0; 3]));
        }
    } else {
        walk(&data, 0, [0; 3], 0, &mut placed)?;
    }
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    let mut boxes = Vec::new();
    for &(m, t) in &placed {
        let model = data.models.get(m as usize).ok_or_else(|| ErrorKind::malformed("vox", format!("shape refers to missing model {m}")))?;
        let size = [model.size.x as i64, model.size.y as i64, model.size.z as i64];
        let min: [i64; 3] = std::array::from_fn(|a| t[a] - size[a] / 2);
        for a in 0..3 {
            lo[a] = lo[a].min(min[a]);
            hi[a] = hi[a].max(min[a] + size[a]);
        }
        boxes.push((model, min));
    }
    if boxes.is_empty() {
        return Err(ErrorKind::malformed("vox", "no models"));
    }
    let dims: [u64; 3] = std::array::from_fn(|a| (hi[a] - lo[a]).max(1) as u64);
    if dims.iter().any(|&d| d > topovox::grid::spec::MAX_DIM as u64) {
        return Err(ErrorKind::malformed("vox", format!("scene spans {dims:?} voxels")));
    }
    let tdims = dims.map(|d| d as u32);
    let recorded = match data.scenes.first() {
        Some(SceneNode::Transform { attributes, .. }) => {
            attributes.get("_topovox_up").or_else(|| attributes.get(crate::former_name::VOX_UP)).and_then(|u| Up::from_name(u))
        }
        _ => None,
    };
    let orient = Orientation::magicavoxel(recorded.unwrap_or(up));
    let dims = orient.source_dims(tdims);
    let mut bits = crate::dense_grid(dims)?;
    let mut coloured = Vec::new();
    for (model, min) in boxes {
        for v in &model.voxels {
            let p = [v.x as i64 + min[0] - lo[0], v.y as i64 + min[1] - lo[1], v.z as i64 + min[2] - lo[2]];
            if (0..3).all(|a| p[a] >= 0 && p[a] < tdims[a] as i64) {
                let p = orient.invert(p.map(|c| c as u32), tdims);
                bits.set(p[0], p[1], p[2]);
                let c = data.palette.get(v.i as usize).map(|c| [c.r, c.g, c.b]).unwrap_or([255; 3]);
                coloured.push((p, c));
            }
        }
    }
    let attributes = Some(VoxelAttributes::from_coloured(dims, coloured));
    Ok(LoadedVoxels { bits, placement: None, attributes })
}

fn walk(data: &DotVoxData, node: u32, t: [i64; 3], depth: u32, out: &mut Vec<(u32, [i64; 3])>) -> Result<(), ErrorKind> {
    if depth > 64 {
        return Err(ErrorKind::malformed("vox", "scene graph deeper than 64 (cycle?)"));
    }
    let n = data.scenes.get(node as usize).ok_or_else(|| ErrorKind::malformed("vox", format!("missing scene node {node}")))?;
    match n {
        SceneNode::Transform { frames, child, .. } => {
            let mut t = t;
            if let Some(f) = frames.first() {
                if f.orientation().is_some_and(|r| format!("{r:?}") != format!("{:?}", dot_vox::Rotation::IDENTITY)) {
                    return Err(ErrorKind::Unsupported("rotated .vox models".into()));
                }
                if let Some(p) = f.position() {
                    t = [t[0] + p.x as i64, t[1] + p.y as i64, t[2] + p.z as i64];
                }
            }
            walk(data, *child, t, depth + 1, out)
        }
        SceneNode::Group { children, .. } => children.iter().try_for_each(|&c| walk(data, c, t, depth + 1, out)),
        SceneNode::Shape { models, .. } => {
            out.extend(models.iter().map(|m| (m.model_id, t)));
            Ok(())
        }
    }
}
