//! Pictures of voxel grids without a GPU: orthographic ray casting through
//! the bricks and then the voxels with a two-level 3D DDA, Blinn–Phong
//! shading with one key light and an ambient term, and gamma.
//!
//! This work is based on: J. Amanatides, A. Woo, "A Fast Voxel Traversal
//! Algorithm for Ray Tracing", Eurographics 1987 (the DDA: per axis the ray
//! parameter of the next cell boundary, step along the smallest), and J. F.
//! Blinn, "Models of Light Reflection for Computer Synthesized Pictures",
//! SIGGRAPH 1977 (the half-vector specular term).
//!
//! Voxel colours, when given, replace the clay colour; a mesh's silhouette
//! outline can be drawn over the picture (its triangles projected with the
//! same camera and rasterized at pixel centres).
//!
//! **Guarantee.** Each pixel shows the first set voxel its ray enters (the
//! voxel, not an approximation: the DDA visits every cell the ray passes
//! through, in order), shaded by the face it enters through. Empty blocks
//! of 64³ voxels and empty 8×8×8 bricks are crossed in one step each (a
//! three-level DDA over [`RenderGrid`], which indexes dense bricks and,
//! for grids past memory, sparse ones alike). The result depends only on the voxels,
//! the options and the image size, not on the thread count.
//!
//! **Reference:** [`reference::first_hit`], the entry parameter of every set
//! voxel's box by the slab test, minimum taken; the tests compare it with
//! [`first_hit`] on random grids and rays.

use glam::DVec3;
use rayon::prelude::*;

use crate::attributes::colour::to_linear;
use crate::attributes::VoxelAttributes;
use crate::grid::bricks::{Brick, BrickBits, BRICK};
use crate::grid::sparse::{SparseBricks, FULL};

/// Bricks per block edge (a block is 64³ voxels).
const BLOCK: u32 = 8;
/// Brick id of a full brick (a sparse solid's interior).
const FULL_ID: u32 = u32::MAX;
/// Largest block index: 2^28 entries (1 GiB), a 2^22-voxel cube.
const MAX_BLOCKS: u64 = 1 << 28;

/// The voxels as the ray caster reads them: an index of 64³-voxel blocks,
/// each non-empty block an index of its 8³ bricks, borrowing the bricks
/// of a [`BrickBits`] or a [`SparseBricks`]. Memory follows the occupied
/// blocks, so grids past a dense brick index (16384³ and beyond) render.
pub struct RenderGrid<'a> {
    dims: [u32; 3],
    /// Blocks along each axis.
    kdims: [u32; 3],
    /// `0` empty, else `1 +` position in `blocks`.
    top: Vec<u32>,
    /// Per block, its 512 bricks (`bi` fastest): `0` empty, [`FULL_ID`],
    /// or `1 +` position in `bricks`.
    blocks: Vec<[u32; 512]>,
    bricks: &'a [Brick],
}

impl<'a> RenderGrid<'a> {
    fn new(dims: [u32; 3], bricks: &'a [Brick]) -> Option<RenderGrid<'a>> {
        let kdims = dims.map(|d| d.div_ceil(BRICK * BLOCK).max(1));
        let n = kdims.iter().map(|&k| k as u64).product::<u64>();
        (n <= MAX_BLOCKS).then(|| RenderGrid { dims, kdims, top: vec![0; n as usize], blocks: Vec::new(), bricks })
    }

    fn insert(&mut self, b: [u32; 3], id: u32) {
        let k = b.map(|c| c / BLOCK);
        let t = (k[2] as usize * self.kdims[1] as usize + k[1] as usize) * self.kdims[0] as usize + k[0] as usize;
        if self.top[t] == 0 {
            self.blocks.push([0; 512]);
            self.top[t] = self.blocks.len() as u32;
        }
        let l = b.map(|c| (c % BLOCK) as usize);
        self.blocks[self.top[t] as usize - 1][(l[2] * 8 + l[1]) * 8 + l[0]] = id;
    }

    /// The bricks of a [`BrickBits`].
    pub fn from_bricks(bits: &'a BrickBits) -> RenderGrid<'a> {
        let (index, bricks) = bits.raw();
        let mut g = RenderGrid::new(bits.dims(), bricks).expect("a brick index's grid has a block index");
        let [bx, by, _] = bits.brick_dims();
        for (n, &id) in index.iter().enumerate() {
            if id != 0 {
                let n = n as u32;
                g.insert([n % bx, n / bx % by, n / bx / by], id);
            }
        }
        g
    }

    /// The bricks of a [`SparseBricks`] (full runs as full bricks), or
    /// `None` for a grid whose block index would pass 1 GiB.
    pub fn from_sparse(bits: &'a SparseBricks) -> Option<RenderGrid<'a>> {
        let mut g = RenderGrid::new(bits.dims(), bits.stored_bits())?;
        for (n, b) in bits.stored_bricks().enumerate() {
            g.insert(b, n as u32 + 1);
        }
        for (b, n) in bits.full_runs() {
            for x in 0..n {
                g.insert([b[0] + x, b[1], b[2]], FULL_ID);
            }
        }
        Some(g)
    }

    /// Voxels along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The 512 brick ids of block `k`, if it holds any.
    #[inline]
    fn block(&self, k: [i64; 3]) -> Option<&[u32; 512]> {
        let t = (k[2] as usize * self.kdims[1] as usize + k[1] as usize) * self.kdims[0] as usize + k[0] as usize;
        match self.top[t] {
            0 => None,
            id => Some(&self.blocks[id as usize - 1]),
        }
    }
}

/// Where the camera looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// Azimuth 45°, elevation 35.26°: the three visible faces of a cube equally lit.
    Iso,
    /// From the positive side of axis 0, 1 or 2, looking back along it.
    Axis(usize),
    /// Azimuth and elevation in degrees, around the up axis (azimuth 0 looks
    /// from the "front" axis, the one after `up`; 90 from the one after that).
    Angles(f64, f64),
}

/// What to draw.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera direction.
    pub view: View,
    /// The world axis drawn pointing up (0, 1 or 2).
    pub up: usize,
    /// Linear RGB of the voxels.
    pub colour: [f64; 3],
    /// A voxel's edge lengths along x, y, z (only their ratios matter), so a
    /// box grid is drawn in its world proportions; `[1, 1, 1]` for cubes.
    pub voxel_shape: [f64; 3],
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions { width: 1024, height: 768, view: View::Iso, up: 1, colour: [0.62, 0.55, 0.46], voxel_shape: [1.0; 3] }
    }
}

/// An 8-bit sRGB image, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width · height · 3` bytes.
    pub rgb: Vec<u8>,
    /// Pixels that show a voxel.
    pub covered: u64,
}

/// The first set voxel along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter where the ray enters the voxel.
    pub t: f64,
    /// The voxel.
    pub voxel: [u32; 3],
    /// The axis of the face it enters through.
    pub axis: usize,
}

/// The camera: orthographic, framing the grid's bounding sphere. It works
/// in *shape space* (index space times the voxel shape, the world up to one
/// factor); rays are handed out, and triangles taken in, in index space.
struct Camera {
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    centre: DVec3,
    radius: f64,
    scale: f64,
    shape: DVec3,
}

fn unit(a: usize) -> DVec3 {
    let mut v = DVec3::ZERO;
    v[a] = 1.0;
    v
}

impl Camera {
    fn new(dims: [u32; 3], o: &RenderOptions) -> Camera {
        let up_axis = o.up.min(2);
        let (front, side) = (unit((up_axis + 1) % 3), unit((up_axis + 2) % 3));
        let world_up = unit(up_axis);
        let towards_camera = match o.view {
            View::Axis(a) => unit(a.min(2)),
            View::Iso => angles(front, side, world_up, 45.0, 35.264_389_682_754_654),
            View::Angles(az, el) => angles(front, side, world_up, az, el),
        };
        let forward = -towards_camera.normalize();
        // Image "up": the world up projected onto the image plane, or the
        // front axis when looking straight along the up axis.
        let reference_up = if forward.dot(world_up).abs() > 0.999 { front } else { world_up };
        let right = forward.cross(reference_up).normalize();
        let up = right.cross(forward).normalize();
        let shape = voxel_shape(o.voxel_shape);
        let size = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * shape;
        let radius = 0.5 * size.length().max(1.0);
        let scale = 2.0 * radius * 1.02 / o.width.min(o.height).max(1) as f64;
        Camera { forward, right, up, centre: size * 0.5, radius, scale, shape }
    }

    /// The ray through the centre of pixel `(x, y)` (row 0 at the top), in
    /// index space.
    fn ray(&self, x: u32, y: u32, w: u32, h: u32) -> (DVec3, DVec3) {
        let sx = (x as f64 + 0.5 - w as f64 * 0.5) * self.scale;
        let sy = (h as f64 * 0.5 - y as f64 - 0.5) * self.scale;
        let origin = self.centre + self.right * sx + self.up * sy - self.forward * (self.radius + 1.0);
        (origin / self.shape, self.forward / self.shape)
    }
}

/// The voxel shape scaled so its smallest edge is 1; cubes for a shape
/// that is not three positive finite numbers.
fn voxel_shape(s: [f64; 3]) -> DVec3 {
    let s = DVec3::from(s);
    if s.is_finite() && s.min_element() > 0.0 {
        s / s.min_element()
    } else {
        DVec3::ONE
    }
}

fn angles(front: DVec3, side: DVec3, up: DVec3, az: f64, el: f64) -> DVec3 {
    let (az, el) = (az.to_radians(), el.to_radians());
    (front * az.cos() + side * az.sin()) * el.cos() + up * el.sin()
}

/// Renders `bits` (rows of pixels in parallel).
pub fn render(bits: &BrickBits, o: &RenderOptions) -> Image {
    render_with(bits, o, None, None)
}

/// [`render`] with voxel colours (`colours`, sRGB, where present) and the
/// outline of a mesh's silhouette (`outline`: triangles in grid units,
/// `grid.to_grid_units(p)`), drawn dark over the picture.
pub fn render_with(bits: &BrickBits, o: &RenderOptions, colours: Option<&VoxelAttributes>, outline: Option<&[[DVec3; 3]]>) -> Image {
    render_grid(&RenderGrid::from_bricks(bits), o, colours, outline)
}

/// [`render_with`] of any [`RenderGrid`] (sparse grids past memory too).
pub fn render_grid(grid: &RenderGrid<'_>, o: &RenderOptions, colours: Option<&VoxelAttributes>, outline: Option<&[[DVec3; 3]]>) -> Image {
    let colours = colours.filter(|c| c.colour.is_some());
    let mut img = shade(grid, o, colours);
    if let Some(tris) = outline {
        let cam = Camera::new(grid.dims(), o);
        let mask = silhouette(&cam, tris, img.width, img.height);
        let (w, h) = (img.width as usize, img.height as usize);
        let inside = |x: i64, y: i64| x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && mask[y as usize * w + x as usize];
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                if !inside(x, y) {
                    continue;
                }
                let edge = (-1..=1).any(|dy| (-1..=1).any(|dx| !inside(x + dx, y + dy)));
                if edge {
                    let at = (y as usize * w + x as usize) * 3;
                    img.rgb[at..at + 3].copy_from_slice(&[24, 26, 34]);
                }
            }
        }
    }
    img
}

/// Pixels whose centre lies inside (or on) a projected triangle.
fn silhouette(cam: &Camera, tris: &[[DVec3; 3]], w: u32, h: u32) -> Vec<bool> {
    let mut mask = vec![false; w as usize * h as usize];
    let project = |p: DVec3| {
        let d = p * cam.shape - cam.centre;
        (d.dot(cam.right) / cam.scale + w as f64 * 0.5 - 0.5, h as f64 * 0.5 - 0.5 - d.dot(cam.up) / cam.scale)
    };
    for t in tris {
        let q = t.map(project);
        if q.iter().any(|p| !p.0.is_finite() || !p.1.is_finite()) {
            continue;
        }
        let area = (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[1].1 - q[0].1) * (q[2].0 - q[0].0);
        if area == 0.0 {
            continue;
        }
        let x0 = q.iter().map(|p| p.0).fold(f64::INFINITY, f64::min).ceil().max(0.0) as i64;
        let x1 = q.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max).floor().min(w as f64 - 1.0) as i64;
        let y0 = q.iter().map(|p| p.1).fold(f64::INFINITY, f64::min).ceil().max(0.0) as i64;
        let y1 = q.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max).floor().min(h as f64 - 1.0) as i64;
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (px, py) = (x as f64, y as f64);
                let inside = (0..3).all(|e| {
                    let (a, b) = (q[e], q[(e + 1) % 3]);
                    ((b.0 - a.0) * (py - a.1) - (b.1 - a.1) * (px - a.0)) * area.signum() >= 0.0
                });
                if inside {
                    mask[y as usize * w as usize + x as usize] = true;
                }
            }
        }
    }
    mask
}

fn shade(bits: &RenderGrid<'_>, o: &RenderOptions, colours: Option<&VoxelAttributes>) -> Image {
    let (w, h) = (o.width.max(1), o.height.max(1));
    let cam = Camera::new(bits.dims(), o);
    // Key light from the upper left, in front of the surface; view vector
    // towards the camera.
    let light = (-cam.forward * 0.55 + cam.up * 0.65 - cam.right * 0.5).normalize();
    let view = -cam.forward;
    let half = (light + view).normalize();
    let background = [0.86, 0.87, 0.89];
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    let covered: u64 = rgb
        .par_chunks_mut(w as usize * 3)
        .enumerate()
        .map(|(y, row)| {
            let mut n = 0;
            for x in 0..w {
                let (origin, dir) = cam.ray(x, y as u32, w, h);
                let lin = match first_hit(bits, origin, dir) {
                    Some(hit) => {
                        n += 1;
                        // The face entered through faces against the ray.
                        let mut normal = unit(hit.axis);
                        if dir[hit.axis] > 0.0 {
                            normal = -normal;
                        }
                        let diffuse = normal.dot(light).max(0.0);
                        let specular = normal.dot(half).max(0.0).powi(32) * 0.25;
                        let base = match colours.and_then(|c| c.colour_of(hit.voxel[0], hit.voxel[1], hit.voxel[2])) {
                            Some(c) => c.map(to_linear),
                            None => o.colour,
                        };
                        base.map(|c| c * (0.22 + 0.78 * diffuse) + specular)
                    }
                    None => background,
                };
                for (c, v) in row[x as usize * 3..x as usize * 3 + 3].iter_mut().zip(lin) {
                    *c = (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0).round() as u8;
                }
            }
            n
        })
        .sum();
    Image { width: w, height: h, rgb, covered }
}

/// The ray `origin + t·dir` clipped to the grid box: `(t_in, t_out, axis of
/// the entry face)`, or `None` if it misses.
fn clip_to_box(dims: [u32; 3], origin: DVec3, dir: DVec3) -> Option<(f64, f64, usize)> {
    let (mut t0, mut t1, mut axis) = (0.0f64, f64::INFINITY, 0);
    for a in 0..3 {
        let hi = dims[a] as f64;
        if dir[a] == 0.0 {
            if origin[a] < 0.0 || origin[a] > hi {
                return None;
            }
            continue;
        }
        let (mut a0, mut a1) = ((0.0 - origin[a]) / dir[a], (hi - origin[a]) / dir[a]);
        if a0 > a1 {
            std::mem::swap(&mut a0, &mut a1);
        }
        if a0 > t0 {
            t0 = a0;
            axis = a;
        }
        t1 = t1.min(a1);
    }
    (t0 <= t1).then_some((t0, t1, axis))
}

/// One level of the DDA: visits, in order, the cells of size `size` that the
/// ray crosses between `t_in` and `t_out`, within the inclusive cell range
/// `[lo, hi]`, with the parameter where it enters each and the axis of the
/// face it enters through. Stops at the first `Some` of `visit`.
fn walk<T>(
    origin: DVec3,
    dir: DVec3,
    (t_in, t_out, entry_axis): (f64, f64, usize),
    size: f64,
    (lo, hi): ([i64; 3], [i64; 3]),
    mut visit: impl FnMut([i64; 3], (f64, f64, usize)) -> Option<T>,
) -> Option<T> {
    let p = origin + dir * t_in;
    let mut cell = [0i64; 3];
    let mut next = [f64::INFINITY; 3];
    let mut delta = [f64::INFINITY; 3];
    let mut step = [0i64; 3];
    for a in 0..3 {
        cell[a] = ((p[a] / size).floor() as i64).clamp(lo[a], hi[a]);
        if dir[a] > 0.0 {
            step[a] = 1;
            next[a] = ((cell[a] + 1) as f64 * size - origin[a]) / dir[a];
            delta[a] = size / dir[a];
        } else if dir[a] < 0.0 {
            step[a] = -1;
            next[a] = (cell[a] as f64 * size - origin[a]) / dir[a];
            delta[a] = -size / dir[a];
        }
    }
    let (mut t, mut axis) = (t_in, entry_axis);
    loop {
        let a = if next[0] <= next[1] && next[0] <= next[2] {
            0
        } else if next[1] <= next[2] {
            1
        } else {
            2
        };
        let leave = next[a].min(t_out);
        if let Some(r) = visit(cell, (t, leave, axis)) {
            return Some(r);
        }
        if next[a] >= t_out {
            return None;
        }
        cell[a] += step[a];
        if cell[a] < lo[a] || cell[a] > hi[a] {
            return None;
        }
        t = next[a];
        axis = a;
        next[a] += delta[a];
    }
}

/// The first set voxel along `origin + t·dir` (`t >= 0`), in voxel units
/// (voxel `(i, j, k)` is the box `[i, i+1] × [j, j+1] × [k, k+1]`):
/// blocks, then their bricks, then the bricks' voxels.
pub fn first_hit(grid: &RenderGrid<'_>, origin: DVec3, dir: DVec3) -> Option<Hit> {
    let dims = grid.dims;
    let span = clip_to_box(dims, origin, dir)?;
    let b = BRICK as i64;
    let kd = grid.kdims.map(|c| c as i64 - 1);
    let bd = dims.map(|c| c.div_ceil(BRICK) as i64 - 1);
    let vd = dims.map(|c| c as i64 - 1);
    walk(origin, dir, span, (BRICK * BLOCK) as f64, ([0; 3], kd), |kc, inner| {
        let block = grid.block(kc)?;
        let blo = kc.map(|c| c * BLOCK as i64);
        let bhi: [i64; 3] = std::array::from_fn(|a| (blo[a] + BLOCK as i64 - 1).min(bd[a]));
        walk(origin, dir, inner, BRICK as f64, (blo, bhi), |bc, (t0, t1, axis)| {
            let l = [0, 1, 2].map(|a| (bc[a] - blo[a]) as usize);
            let brick = match block[(l[2] * 8 + l[1]) * 8 + l[0]] {
                0 => return None,
                FULL_ID => &FULL,
                id => &grid.bricks[id as usize - 1],
            };
            let lo = bc.map(|c| c * b);
            let hi: [i64; 3] = std::array::from_fn(|a| (lo[a] + b - 1).min(vd[a]));
            walk(origin, dir, (t0, t1, axis), 1.0, (lo, hi), |v, (t, _, axis)| {
                let (x, y, z) = (v[0] as u32 & 7, v[1] as u32 & 7, v[2] as u32 & 7);
                ((brick[z as usize] >> (y * 8 + x)) & 1 == 1).then_some(Hit { t, voxel: v.map(|c| c as u32), axis })
            })
        })
    })
}

/// The slow, obviously correct first hit.
pub mod reference {
    use super::*;

    /// The set voxel whose box the ray enters first (ties: the first in
    /// `k`, `j`, `i` order), by the slab test against every set voxel.
    pub fn first_hit(bits: &BrickBits, origin: DVec3, dir: DVec3) -> Option<([u32; 3], f64)> {
        let mut best: Option<([u32; 3], f64)> = None;
        bits.for_each_set(|i, j, k| {
            let lo = DVec3::new(i as f64, j as f64, k as f64);
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            for a in 0..3 {
                if dir[a] == 0.0 {
                    if origin[a] < lo[a] || origin[a] > lo[a] + 1.0 {
                        return;
                    }
                    continue;
                }
                let (p, q) = ((lo[a] - origin[a]) / dir[a], (lo[a] + 1.0 - origin[a]) / dir[a]);
                t0 = t0.max(p.min(q));
                t1 = t1.min(p.max(q));
            }
            if t0 <= t1 && best.is_none_or(|(_, bt)| t0 < bt) {
                best = Some(([i, j, k], t0));
            }
        });
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(dims: [u32; 3], voxels: &[[u32; 3]]) -> BrickBits {
        let mut b = BrickBits::new(dims);
        for v in voxels {
            b.set(v[0], v[1], v[2]);
        }
        b
    }

    /// The DDA's hit and the slab test's agree (rays through a shared edge
    /// or corner may report a different voxel at the same parameter).
    fn assert_same_hit(fast: Option<Hit>, slow: Option<([u32; 3], f64)>, round: usize) {
        match (fast, slow) {
            (None, None) => {}
            (Some(h), Some((v, t))) => assert!((h.t - t).abs() < 1e-9, "round {round}: t {} vs {t} ({:?} vs {v:?})", h.t, h.voxel),
            (a, b) => panic!("round {round}: {a:?} vs {b:?}"),
        }
    }

    #[test]
    fn dda_finds_the_same_first_voxel_as_the_slab_test() {
        let mut rng = crate::test_rng::Xorshift(0x9e37_79b9_7f4a_7c15);
        let mut r = || rng.next_u64();
        for round in 0..60 {
            let dims = [5 + (r() % 20) as u32, 5 + (r() % 20) as u32, 5 + (r() % 20) as u32];
            let n = 1 + r() % 40;
            let voxels: Vec<[u32; 3]> = (0..n).map(|_| std::array::from_fn(|a| (r() % dims[a] as u64) as u32)).collect();
            let bits = grid(dims, &voxels);
            let g = RenderGrid::from_bricks(&bits);
            for _ in 0..200 {
                let f = |r: &mut dyn FnMut() -> u64| (r() % 20_000) as f64 / 1000.0 - 10.0;
                let origin = DVec3::new(f(&mut r) * 3.0, f(&mut r) * 3.0, f(&mut r) * 3.0);
                let target = DVec3::new(f(&mut r).abs() * 2.0, f(&mut r).abs() * 2.0, f(&mut r).abs() * 2.0);
                let dir = (target - origin).normalize();
                assert_same_hit(first_hit(&g, origin, dir), reference::first_hit(&bits, origin, dir), round);
            }
        }
    }

    /// Sparse bricks with runs of full bricks, over several 64³ blocks,
    /// give the same hits as the same voxels in a [`BrickBits`] and as the
    /// slab test, and the same pictures.
    #[test]
    fn sparse_grids_over_many_blocks_render_like_dense_ones() {
        let mut rng = crate::test_rng::Xorshift(0x2545_f491_4f6c_dd1d);
        let mut r = || rng.next_u64();
        for round in 0..6 {
            let dims = [70 + (r() % 120) as u32, 65 + (r() % 100) as u32, 66 + (r() % 90) as u32];
            let mut dense = BrickBits::new(dims);
            for _ in 0..300 {
                let v: [u32; 3] = std::array::from_fn(|a| (r() % dims[a] as u64) as u32);
                dense.set(v[0], v[1], v[2]);
            }
            // A run of full bricks along bi, away from the random voxels' bricks.
            let b = [1 + (r() % 3) as u32, (r() % (dims[1] as u64 / 8)) as u32, (r() % (dims[2] as u64 / 8)) as u32];
            let run = 1 + (r() % 4) as u32;
            let mut stored = Vec::new();
            let d = dense.to_dense();
            crate::grid::VoxelSource::for_each_brick(&d, &mut |c, bits| {
                if !(c[1] == b[1] && c[2] == b[2] && c[0] >= b[0] && c[0] < b[0] + run) {
                    stored.push((c, *bits));
                }
            });
            let sparse = SparseBricks::from_parts(dims, stored, vec![(b, run)]);
            let full = BrickBits::from_source(&sparse);
            let (gs, gd) = (RenderGrid::from_sparse(&sparse).unwrap(), RenderGrid::from_bricks(&full));
            for _ in 0..150 {
                let f = |r: &mut dyn FnMut() -> u64, n: u32| (r() % (n as u64 * 3000)) as f64 / 1000.0 - n as f64;
                let origin = DVec3::new(f(&mut r, dims[0]), f(&mut r, dims[1]), f(&mut r, dims[2]));
                let target = DVec3::new(f(&mut r, dims[0]).abs(), f(&mut r, dims[1]).abs(), f(&mut r, dims[2]).abs());
                let dir = (target - origin).normalize();
                let (a, b) = (first_hit(&gs, origin, dir), first_hit(&gd, origin, dir));
                assert_eq!(a, b, "round {round}");
                assert_same_hit(a, reference::first_hit(&full, origin, dir), round);
            }
            let o = RenderOptions { width: 96, height: 72, ..RenderOptions::default() };
            assert_eq!(render_grid(&gs, &o, None, None), render(&full, &o), "round {round}");
        }
    }

    #[test]
    fn one_voxel_in_the_middle_of_the_picture() {
        let bits = grid([3, 3, 3], &[[1, 1, 1]]);
        for view in [View::Iso, View::Axis(0), View::Axis(1), View::Axis(2), View::Angles(200.0, -30.0)] {
            let img = render(&bits, &RenderOptions { width: 64, height: 48, view, ..RenderOptions::default() });
            assert_eq!(img.rgb.len(), 64 * 48 * 3);
            let px = |x: usize, y: usize| &img.rgb[(y * 64 + x) * 3..(y * 64 + x) * 3 + 3];
            assert_ne!(px(32, 24), px(0, 0), "{view:?}: centre shows the voxel");
            assert_eq!(px(0, 0), px(63, 47), "{view:?}: corners show the background");
            assert!(img.covered > 0 && img.covered < 64 * 48 / 4, "{view:?}: {}", img.covered);
        }
    }

    #[test]
    fn boxes_are_drawn_in_their_proportions() {
        // One voxel four times as tall (y) as wide, seen along z: the
        // covered pixels span four times as many rows as columns.
        let bits = grid([1, 1, 1], &[[0, 0, 0]]);
        let o = RenderOptions { width: 200, height: 200, view: View::Axis(2), voxel_shape: [0.5, 2.0, 0.5], ..RenderOptions::default() };
        let img = render(&bits, &o);
        let bg = img.rgb[..3].to_vec();
        let (mut rows, mut cols) = (std::collections::BTreeSet::new(), std::collections::BTreeSet::new());
        for (n, p) in img.rgb.chunks(3).enumerate() {
            if p != bg.as_slice() {
                rows.insert(n / 200);
                cols.insert(n % 200);
            }
        }
        let ratio = rows.len() as f64 / cols.len() as f64;
        assert!((ratio - 4.0).abs() < 0.2, "{} rows, {} columns", rows.len(), cols.len());
        // Cubes: square.
        let cube = render(&bits, &RenderOptions { voxel_shape: [3.0; 3], ..o });
        assert_eq!(cube, render(&bits, &RenderOptions { voxel_shape: [1.0; 3], ..o }));
    }

    #[test]
    fn lit_faces_differ_and_the_picture_is_deterministic() {
        let bits = grid([4, 4, 4], &[[1, 1, 1], [2, 1, 1], [1, 2, 1], [1, 1, 2]]);
        let o = RenderOptions { width: 80, height: 60, ..RenderOptions::default() };
        let a = render(&bits, &o);
        let b = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| render(&bits, &o));
        assert_eq!(a, b);
        let mut shades: Vec<&[u8]> = a.rgb.chunks(3).collect();
        shades.sort();
        shades.dedup();
        assert!(shades.len() >= 4, "background and three face shades: {}", shades.len());
    }
}
