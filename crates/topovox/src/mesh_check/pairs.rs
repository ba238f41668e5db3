//! The self-intersection count's broad phase: face boxes binned in a
//! uniform grid of cells the size of the mean box, each pair of faces whose
//! boxes overlap tested once — in the cell holding the low corner of the
//! two boxes' overlap — by the exact tests of [`super::intersect`].

use glam::DVec3;
use rayon::prelude::*;

use super::intersect::{improper, meet};
use crate::stop::Stop;

/// Most cells along an axis (the grid's memory is per face, not per cell).
const MAX_CELLS: f64 = 1048576.0;

/// Faces whose box spans more cells than this are tested against every
/// face by box instead (a few huge faces must not fill the grid).
const MAX_SPAN: u64 = 64;

/// The pairs of faces (sorted, `[lower, higher]`) that meet beyond what
/// they share; degenerate faces are left out. `None` when stopped.
pub fn intersecting(pos: &[DVec3], faces: &[[u32; 3]], degenerate: &[bool], stop: &Stop) -> Option<Vec<[u32; 2]>> {
    let boxes: Vec<(DVec3, DVec3)> = faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| pos[v as usize]);
            (a.min(b).min(c), a.max(b).max(c))
        })
        .collect();
    let live: Vec<u32> = (0..faces.len() as u32).filter(|&f| !degenerate[f as usize]).collect();
    if live.len() < 2 {
        return Some(Vec::new());
    }
    let (lo, hi) =
        live.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), &f| (l.min(boxes[f as usize].0), h.max(boxes[f as usize].1)));
    let mean = live.iter().map(|&f| boxes[f as usize].1 - boxes[f as usize].0).fold(DVec3::ZERO, |s, e| s + e) / live.len() as f64;
    let size = mean.max_element().max((hi - lo).max_element() / MAX_CELLS).max(f64::MIN_POSITIVE);
    let cell = |p: DVec3| ((p - lo) / size).floor().as_uvec3().min(glam::UVec3::splat(MAX_CELLS as u32)).to_array();
    let n = cell(hi).map(|c| c as u64 + 1);
    let key = |c: [u32; 3]| (c[2] as u64 * n[1] + c[1] as u64) * n[0] + c[0] as u64;
    let mut entries: Vec<(u64, u32)> = Vec::new();
    let mut big = Vec::new();
    for &f in &live {
        let (a, b) = (cell(boxes[f as usize].0), cell(boxes[f as usize].1));
        if (0..3).map(|k| (b[k] - a[k]) as u64 + 1).product::<u64>() > MAX_SPAN {
            big.push(f);
            continue;
        }
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    entries.push((key([x, y, z]), f));
                }
            }
        }
    }
    entries.par_sort_unstable();
    let groups: Vec<&[(u64, u32)]> = entries.chunk_by(|a, b| a.0 == b.0).filter(|g| g.len() > 1).collect();
    let found: Option<Vec<Vec<[u32; 2]>>> = groups
        .par_iter()
        .map(|g| {
            if stop.requested() {
                return None;
            }
            let mut out = Vec::new();
            for (n, &(c, f)) in g.iter().enumerate() {
                for &(_, h) in &g[n + 1..] {
                    let (bf, bh) = (boxes[f as usize], boxes[h as usize]);
                    let (olo, ohi) = (bf.0.max(bh.0), bf.1.min(bh.1));
                    if olo.cmpgt(ohi).any() || key(cell(olo)) != c {
                        continue;
                    }
                    if faces_meet(pos, &faces[f as usize], &faces[h as usize]) {
                        out.push([f.min(h), f.max(h)]);
                    }
                }
            }
            Some(out)
        })
        .collect();
    let mut pairs: Vec<[u32; 2]> = found?.into_iter().flatten().collect();
    pairs.extend(big_pairs(pos, faces, &boxes, &live, &big, stop)?);
    pairs.sort_unstable();
    Some(pairs)
}

/// The pairs with a big face, by box overlap against every live face
/// (a pair of big faces once).
fn big_pairs(pos: &[DVec3], faces: &[[u32; 3]], boxes: &[(DVec3, DVec3)], live: &[u32], big: &[u32], stop: &Stop) -> Option<Vec<[u32; 2]>> {
    let is_big = |f: u32| big.binary_search(&f).is_ok();
    let found: Option<Vec<Vec<[u32; 2]>>> = big
        .par_iter()
        .map(|&f| {
            if stop.requested() {
                return None;
            }
            let bf = boxes[f as usize];
            let others = live.iter().filter(|&&h| h != f && !(is_big(h) && h < f));
            let overlapping = others.filter(|&&h| !(bf.0.cmpgt(boxes[h as usize].1).any() || boxes[h as usize].0.cmpgt(bf.1).any()));
            Some(overlapping.filter(|&&h| faces_meet(pos, &faces[f as usize], &faces[h as usize])).map(|&h| [f.min(h), f.max(h)]).collect())
        })
        .collect();
    Some(found?.into_iter().flatten().collect())
}

/// Whether two non-degenerate faces meet beyond the vertices they share.
pub(super) fn faces_meet(pos: &[DVec3], f: &[u32; 3], h: &[u32; 3]) -> bool {
    let a = f.map(|v| pos[v as usize]);
    let b = h.map(|v| pos[v as usize]);
    let shared: Vec<(usize, usize)> = (0..3).flat_map(|i| (0..3).filter(move |&j| f[i] == h[j]).map(move |j| (i, j))).collect();
    match shared.len() {
        0 => meet(&a, &b),
        1 | 2 => improper(&a, &b, &shared),
        _ => true,
    }
}
