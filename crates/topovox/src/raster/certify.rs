//! Certifying 2D pixel sets: connectivity (4 or 8) and separation of a
//! closed curve's inside from its outside.
//!
//! Separation needs no flood fill: a path of unset pixels from inside to
//! outside must step between two adjacent unset pixels of different class,
//! so it is enough to compare every pair of adjacent unset pixels. Classes
//! are the nonzero winding at the displaced pixel centre, as in `fill`.

use super::predicates::winding_crossing;
use super::{Grid2, Outline, Pixels};

/// 4- (edge) or 8- (edge or corner) adjacency.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Adjacency {
    /// Through edges.
    Four,
    /// Through edges or corners.
    Eight,
}

impl Adjacency {
    fn offsets(self) -> &'static [[i64; 2]] {
        match self {
            Adjacency::Four => &[[1, 0], [0, 1]],
            Adjacency::Eight => &[[1, 0], [0, 1], [1, 1], [1, -1]],
        }
    }
}

/// Connected components of the set pixels under `adj`.
pub fn components(px: &Pixels, adj: Adjacency) -> usize {
    let [nx, ny] = px.dims().map(|d| d as i64);
    let mut seen = vec![false; (nx * ny) as usize];
    let mut n = 0;
    let mut stack = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if !px.get(i, j) || seen[(j * nx + i) as usize] {
                continue;
            }
            n += 1;
            seen[(j * nx + i) as usize] = true;
            stack.push([i, j]);
            while let Some([a, b]) = stack.pop() {
                for o in adj.offsets() {
                    for s in [1, -1] {
                        let (x, y) = (a + s * o[0], b + s * o[1]);
                        if px.get(x, y) && !seen[(y * nx + x) as usize] {
                            seen[(y * nx + x) as usize] = true;
                            stack.push([x, y]);
                        }
                    }
                }
            }
        }
    }
    n
}

/// Inside (nonzero winding at the displaced centre) per pixel, for the
/// outlines taken as closed.
pub fn inside(outlines: &[Outline], grid: &Grid2) -> Vec<bool> {
    let closed: Vec<Outline> = outlines.iter().map(Outline::closed).collect();
    let (edges, _) = super::snap_segments(&closed, grid);
    let [nx, ny] = grid.dims().map(|d| d as i64);
    let h = crate::geom::fixed::ONE / 2;
    let mut out = Vec::with_capacity((nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let c = [i * crate::geom::fixed::ONE + h, j * crate::geom::fixed::ONE + h];
            out.push(edges.iter().map(|&[u, v]| winding_crossing(u, v, c)).sum::<i32>() != 0);
        }
    }
    out
}

/// Two `adj`-adjacent unset pixels, one inside and one outside, if any:
/// `None` means the set separates the inside from the outside.
pub fn separation_witness(px: &Pixels, inside: &[bool], adj: Adjacency) -> Option<[[u32; 2]; 2]> {
    let [nx, ny] = px.dims().map(|d| d as i64);
    for j in 0..ny {
        for i in 0..nx {
            if px.get(i, j) {
                continue;
            }
            for o in adj.offsets() {
                let (x, y) = (i + o[0], j + o[1]);
                if x < 0 || y < 0 || x >= nx || y >= ny || px.get(x, y) {
                    continue;
                }
                if inside[(j * nx + i) as usize] != inside[(y * nx + x) as usize] {
                    return Some([[i as u32, j as u32], [x as u32, y as u32]]);
                }
            }
        }
    }
    None
}
