//! Curves in 2D: `curve4`, `curve8`, `diamond`.
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §4.
//!
//! **Targets** of pixel `(i, j)` with corner `c = (i, j)·s` and half side `h`:
//! - `curve4`: the two diagonals `c → c + (s, s)` and `c + (s, 0) → c + (0, s)`
//!   (Fig. 5c). **Guarantee:** a polyline gives a 4-connected set that is
//!   8-separating (a closed curve's inside and outside pixels are not
//!   8-adjacent).
//! - `curve8`: the crosshair `c + (0, h) → c + (s, h)` and `c + (h, 0) → c +
//!   (h, s)` (Fig. 7c). **Guarantee:** 8-connected and 4-separating.
//! - `diamond`: the closed diamond with vertices at the side midpoints
//!   (Fig. 7d), the rule graphics APIs use for lines. **Guarantee:** as
//!   `curve8` (the diamond is the crosshair's convex hull).
//!
//! A pixel is set iff a segment meets its target, displaced by `δ = −(ε,
//! ε²)`. Every target lies in the closed pixel.
//!
//! **Fast path.** Per segment, the columns it spans; per column, the rows
//! its exact `y` range there covers (pixels whose closed square it meets),
//! each tested against its target. Work proportional to length.
//!
//! **Reference:** [`reference::curve`], every pixel of each segment's
//! bounding box.

use super::predicates::{point_in_target, segment_meets_target};
use super::{snap_segments, Grid2, Outline, Pixels, RasterMode, RasterReport, P2};
use crate::geom::fixed::{voxel_span, ONE};

const H: i64 = ONE / 2;

/// Does segment `s` meet pixel `(i, j)`'s target in `mode` (a curve mode)?
pub fn hit(mode: RasterMode, s: [P2; 2], i: i64, j: i64) -> bool {
    let (x, y) = (i * ONE, j * ONE);
    match mode {
        RasterMode::Curve4 => {
            segment_meets_target(s, [[x, y], [x + ONE, y + ONE]]) || segment_meets_target(s, [[x + ONE, y], [x, y + ONE]])
        }
        RasterMode::Curve8 => {
            segment_meets_target(s, [[x, y + H], [x + ONE, y + H]]) || segment_meets_target(s, [[x + H, y], [x + H, y + ONE]])
        }
        RasterMode::Diamond => {
            let d = [[x + H, y], [x + ONE, y + H], [x + H, y + ONE], [x, y + H]];
            (0..4).any(|k| segment_meets_target(s, [d[k], d[(k + 1) % 4]])) || point_in_target(s[0], &d) || point_in_target(s[1], &d)
        }
        RasterMode::Fill => false,
    }
}

/// The fast path of a curve mode.
pub fn curve(mode: RasterMode, outlines: &[Outline], grid: &Grid2) -> (Pixels, RasterReport) {
    let (segs, mut rep) = snap_segments(outlines, grid);
    let dims = grid.dims().map(|d| d as i64);
    let mut px = Pixels::new(grid.dims());
    for s in &segs {
        let [a, b] = *s;
        let (xa, xb) = (a[0].min(b[0]), a[0].max(b[0]));
        let (c0, c1) = voxel_span(xa, xb);
        for i in c0.max(0)..=c1.min(dims[0] - 1) {
            // The segment's y range over the column's closed x range.
            let (x0, x1) = ((i * ONE).max(xa), ((i + 1) * ONE).min(xb));
            let (ylo, yhi) = if a[0] == b[0] {
                (a[1].min(b[1]), a[1].max(b[1]))
            } else {
                let y_at = |x: i64, up: bool| {
                    // y(x) = a.y + (b.y − a.y)(x − a.x)/(b.x − a.x), rounded outwards.
                    let (n, d) = ((b[1] - a[1]) as i128 * (x - a[0]) as i128, (b[0] - a[0]) as i128);
                    let (n, d) = if d < 0 { (-n, -d) } else { (n, d) };
                    let q = n.div_euclid(d) + if up && n.rem_euclid(d) != 0 { 1 } else { 0 };
                    a[1] + q as i64
                };
                let (ya, yb) = (y_at(x0, false).min(y_at(x1, false)), y_at(x0, true).max(y_at(x1, true)));
                (ya, yb)
            };
            let (r0, r1) = voxel_span(ylo, yhi);
            for j in r0.max(0)..=r1.min(dims[1] - 1) {
                if !px.get(i, j) && hit(mode, *s, i, j) {
                    px.set(i as u32, j as u32);
                }
            }
        }
    }
    rep.pixels = px.count();
    (px, rep)
}

/// The slow, obviously correct definition.
pub mod reference {
    use super::*;

    /// Every pixel of each segment's bounding box against its target.
    pub fn curve(mode: RasterMode, outlines: &[Outline], grid: &Grid2) -> (Pixels, RasterReport) {
        let (segs, mut rep) = snap_segments(outlines, grid);
        let dims = grid.dims().map(|d| d as i64);
        let mut px = Pixels::new(grid.dims());
        for s in &segs {
            let (x0, x1) = voxel_span(s[0][0].min(s[1][0]), s[0][0].max(s[1][0]));
            let (y0, y1) = voxel_span(s[0][1].min(s[1][1]), s[0][1].max(s[1][1]));
            for j in y0.max(0)..=y1.min(dims[1] - 1) {
                for i in x0.max(0)..=x1.min(dims[0] - 1) {
                    if hit(mode, *s, i, j) {
                        px.set(i as u32, j as u32);
                    }
                }
            }
        }
        rep.pixels = px.count();
        (px, rep)
    }
}
