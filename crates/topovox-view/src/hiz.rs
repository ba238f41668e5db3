//! Hierarchical-Z occlusion culling (seed 002, § "occlusion culling"):
//! the CPU reference of what `hiz.wgsl` and `cull.wgsl` do.
//!
//! - **Pyramid.** Level 0 holds the depth of the frustum survivors drawn
//!   depth-only, at the picture's own resolution, padded to powers of two
//!   with 0 (no fragment ever lands in the padding, so any value there is
//!   safe; 0 never raises a maximum). Each further level keeps the
//!   **maximum** depth of the 2×2 texels below it, down to 1×1.
//! - **Test.** A cluster's box is projected (its eight corners); if any
//!   corner is at or behind the eye plane (`w ≤ 0`) it is kept. Otherwise
//!   the rectangle of pixels it can touch, widened by one pixel for
//!   rounding, is looked up at the finest level where it spans at most 2×2
//!   texels; the box is culled when its nearest depth exceeds the largest
//!   of those (at most four) depths by more than [`DEPTH_EPS`].
//!
//! **Why the picture cannot change.** The depth pass draws every frustum
//! survivor with the shading pass's vertex shader (`@invariant` position),
//! so level 0 is the final depth buffer. The nearest depth of a box bounds
//! every fragment of its triangles from below (depth is an affine function
//! of view depth, minimal at a corner), and the pyramid bounds every pixel
//! of the rectangle from above; a culled cluster's fragments would all
//! fail the `Less` depth test. The report renders this pass into a reduced
//! 512×256 framebuffer instead; sampled at lower resolution, depth is no
//! longer a bound, so topovox renders it at full resolution and finds the
//! report's reduced levels in the pyramid above it.

use glam::{Mat4, Vec3, Vec4};

/// Margin on depth comparisons (about 16 ulps near 1).
pub const DEPTH_EPS: f32 = 1e-6;

/// A depth pyramid: level `l` is `sizes[l]` texels, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    /// Width and height per level.
    pub sizes: Vec<[u32; 2]>,
    /// Depths per level.
    pub levels: Vec<Vec<f32>>,
    /// The picture's size (level 0 is padded from it).
    pub picture: [u32; 2],
}

/// Level-0 size and level count for a picture.
pub fn pyramid_size(width: u32, height: u32) -> ([u32; 2], u32) {
    let (w, h) = (width.next_power_of_two(), height.next_power_of_two());
    (([w, h]), w.max(h).trailing_zeros() + 1)
}

impl Pyramid {
    /// Builds the pyramid of a `width × height` depth picture.
    pub fn build(depth: &[f32], width: u32, height: u32) -> Pyramid {
        let ([w0, h0], count) = pyramid_size(width, height);
        let mut level0 = vec![0.0f32; (w0 * h0) as usize];
        for y in 0..height as usize {
            level0[y * w0 as usize..y * w0 as usize + width as usize].copy_from_slice(&depth[y * width as usize..(y + 1) * width as usize]);
        }
        let mut p = Pyramid { sizes: vec![[w0, h0]], levels: vec![level0], picture: [width, height] };
        for _ in 1..count {
            let [sw, sh] = *p.sizes.last().expect("level 0");
            let src = p.levels.last().expect("level 0");
            let (dw, dh) = ((sw / 2).max(1), (sh / 2).max(1));
            let mut dst = vec![0.0f32; (dw * dh) as usize];
            for y in 0..dh {
                for x in 0..dw {
                    let mut m = 0.0f32;
                    for (sx, sy) in [(2 * x, 2 * y), (2 * x + 1, 2 * y), (2 * x, 2 * y + 1), (2 * x + 1, 2 * y + 1)] {
                        m = m.max(src[(sy.min(sh - 1) * sw + sx.min(sw - 1)) as usize]);
                    }
                    dst[(y * dw + x) as usize] = m;
                }
            }
            p.sizes.push([dw, dh]);
            p.levels.push(dst);
        }
        p
    }

    /// The texel of level `l` at `(x, y)` (clamped to the level).
    fn at(&self, l: usize, x: u32, y: u32) -> f32 {
        let [w, h] = self.sizes[l];
        self.levels[l][(y.min(h - 1) * w + x.min(w - 1)) as usize]
    }

    /// The occlusion test of one box (see the module doc): true when culled.
    pub fn occluded(&self, lo: Vec3, hi: Vec3, view_proj: &Mat4) -> bool {
        let Some((rect, min_z)) = screen_rect(lo, hi, view_proj, self.picture) else { return false };
        let [x0, y0, x1, y1] = rect;
        let mut l = 0;
        while l + 1 < self.sizes.len() && ((x1 >> l) - (x0 >> l) > 1 || (y1 >> l) - (y0 >> l) > 1) {
            l += 1;
        }
        let mut d = 0.0f32;
        for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            d = d.max(self.at(l, x >> l, y >> l));
        }
        min_z > d + DEPTH_EPS
    }
}

/// Clip coordinates of `p`, column by column in the shader's order.
fn clip(m: &Mat4, p: Vec3) -> Vec4 {
    ((m.x_axis * p.x + m.y_axis * p.y) + m.z_axis * p.z) + m.w_axis
}

/// The pixel rectangle `[x0, y0, x1, y1]` (inclusive, clamped to the
/// picture, widened by a pixel) a box can touch and its nearest depth;
/// `None` when a corner is at or behind the eye plane.
pub fn screen_rect(lo: Vec3, hi: Vec3, view_proj: &Mat4, picture: [u32; 2]) -> Option<([u32; 4], f32)> {
    let (mut nlo, mut nhi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in 0..8 {
        let p = Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z });
        let q = clip(view_proj, p);
        if q.w <= 0.0 {
            return None;
        }
        let n = q.truncate() / q.w;
        nlo = nlo.min(n);
        nhi = nhi.max(n);
    }
    let (w, h) = (picture[0] as f32, picture[1] as f32);
    // Pixels: x right from the left edge, y down from the top edge.
    let px = |ndc: f32| ((ndc * 0.5 + 0.5) * w).floor();
    let py = |ndc: f32| ((0.5 - ndc * 0.5) * h).floor();
    let clampi = |v: f32, max: f32| v.clamp(0.0, max) as u32;
    let x0 = clampi(px(nlo.x) - 1.0, w - 1.0);
    let x1 = clampi(px(nhi.x) + 1.0, w - 1.0);
    let y0 = clampi(py(nhi.y) - 1.0, h - 1.0);
    let y1 = clampi(py(nlo.y) + 1.0, h - 1.0);
    Some(([x0, y0, x1, y1], nlo.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_keep_the_maximum_and_odd_sizes_are_padded() {
        let (w, h) = (5u32, 3u32);
        let depth: Vec<f32> = (0..w * h).map(|i| i as f32 / 20.0).collect();
        let p = Pyramid::build(&depth, w, h);
        assert_eq!(p.sizes, vec![[8, 4], [4, 2], [2, 1], [1, 1]]);
        let top = p.levels.last().unwrap()[0];
        assert_eq!(top, depth.iter().cloned().fold(0.0, f32::max));
        // Every texel of every level bounds the level-0 texels below it.
        for l in 1..p.sizes.len() {
            for y in 0..h {
                for x in 0..w {
                    assert!(p.at(l, x >> l, y >> l) >= depth[(y * w + x) as usize]);
                }
            }
        }
    }

    #[test]
    fn a_box_behind_a_wall_is_culled_and_one_in_front_is_not() {
        let cam = crate::Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_deg: 60.0 };
        let m = cam.view_proj(1.0, 0.1, 100.0);
        // A wall at z = 0 filling the view: its depth everywhere.
        let wall = clip(&m, Vec3::ZERO);
        let d = wall.z / wall.w;
        let p = Pyramid::build(&vec![d; 64 * 64], 64, 64);
        let unit = Vec3::splat(0.3);
        assert!(p.occluded(Vec3::new(0.0, 0.0, -2.0) - unit, Vec3::new(0.0, 0.0, -2.0) + unit, &m));
        assert!(!p.occluded(Vec3::new(0.0, 0.0, 2.0) - unit, Vec3::new(0.0, 0.0, 2.0) + unit, &m));
        // Straddling the wall: kept.
        assert!(!p.occluded(Vec3::splat(-0.3), Vec3::splat(0.3), &m));
        // Around the eye: kept.
        assert!(!p.occluded(Vec3::new(-1.0, -1.0, 4.0), Vec3::new(1.0, 1.0, 6.0), &m));
    }
}
