//! Grid operations on solids: flood fill against a surface shell, and
//! hollowing.
//!
//! **Flood fill.** Given a shell (a surface voxelization), the result is
//! every voxel *not* reachable from the grid's boundary through unset
//! voxels by 6-connected steps: the shell plus everything it encloses. A
//! 26-separating shell (`cover`, `sep26`) cannot be crossed by a 6-connected
//! path of unset voxels only where it is closed; where the surface has a
//! hole wider than the shell, the fill leaks and the enclosed volume is
//! lost — [`FloodReport::enclosed`] says how much was found. Unset voxels
//! are grouped into runs along `i` and joined with union–find, so the cost
//! is proportional to the number of runs, not voxels.
//!
//! **Hollow.** Keeps the voxels of a solid that have a 6- (or 26-)
//! neighbour outside it (or lie on the grid's boundary): a one-voxel skin,
//! as for Minecraft-style builds. [`hollow_sparse`] does the same on sparse
//! bricks with runs of full bricks (solids past memory): a full brick
//! whose neighbour bricks are all full keeps nothing, and those are found
//! row by row by intersecting intervals of full bricks, so the interior is
//! never visited brick by brick; every other brick is skinned with its
//! 3×3×3 neighbourhood of bricks. Tested against [`hollow`].

use rayon::prelude::*;

use std::collections::HashMap;

use super::solid::{bricks_of_spans, from_brick_rows, push_span, BrickRow};
use super::Stop;
use crate::grid::bricks::{Brick, BRICK};
use crate::grid::dense::DenseBits;
use crate::grid::sparse::SparseBricks;
use crate::topology::runs::{components, Connectivity, Runs, StreamedComponents};

/// What a flood fill found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FloodReport {
    /// Voxels of the shell.
    pub shell: u64,
    /// Unset voxels the shell encloses (added by the fill).
    pub enclosed: u64,
}

/// The shell plus every unset voxel not 6-connected to the grid boundary.
pub fn flood_fill(shell: &DenseBits) -> (DenseBits, FloodReport) {
    let [nx, ny, nz] = shell.dims();
    let runs = Runs::of(shell, false);
    let (labels, _) = components(&runs, Connectivity::Six);
    let mut outside = vec![false; runs.len()];
    for r in 0..ny as usize * nz as usize {
        let (j, k) = runs.row_jk(r);
        let edge_row = j == 0 || k == 0 || j == ny - 1 || k == nz - 1;
        for a in runs.row_runs(r) {
            if edge_row || runs.start[a] == 0 || runs.end[a] == nx - 1 {
                outside[labels[a] as usize] = true;
            }
        }
    }
    let mut out = shell.clone();
    let enclosed: u64 = out
        .par_rows_mut()
        .enumerate()
        .map(|(r, row)| {
            let mut n = 0;
            for a in runs.row_runs(r) {
                if !outside[labels[a] as usize] {
                    DenseBits::fill_row(row, runs.start[a], runs.end[a]);
                    n += (runs.end[a] - runs.start[a] + 1) as u64;
                }
            }
            n
        })
        .sum();
    (out, FloodReport { shell: shell.count(), enclosed })
}

/// [`flood_fill`] without a dense grid, for shells past memory: plane by
/// plane, the unset runs of each plane are joined with those of the plane
/// before ([`StreamedComponents`]: labels only for each plane's 2D
/// components), components touching the grid's boundary are marked
/// outside, and a second pass emits the shell plus the enclosed runs
/// brick row by brick row, enclosed interiors as runs of full bricks. The
/// same voxels and report as [`flood_fill`]. Planes and layers are skipped
/// once `stop` is requested.
///
/// Every unset voxel outside the box of the shell's bricks reaches the
/// grid's boundary in a straight line (along an axis on which it lies past
/// the box), so the fill runs on that box grown by a brick on each side
/// (clamped to the grid), whose faces are then outside or the grid's own:
/// its time and memory follow the shell, not the grid (a small shell in a
/// 65536³ grid walked 65536 planes of 65536 rows).
pub fn flood_fill_sparse(shell: &SparseBricks, stop: &Stop) -> (SparseBricks, FloodReport) {
    let dims = shell.dims();
    let Some((lo, hi)) = shell.brick_bounds() else {
        return (SparseBricks::new(dims), FloodReport { shell: 0, enclosed: 0 });
    };
    let bdims = dims.map(|d| d.div_ceil(BRICK));
    let lo = lo.map(|b| b.saturating_sub(1));
    let hi: [u32; 3] = std::array::from_fn(|a| (hi[a] + 1).min(bdims[a] - 1));
    if lo == [0; 3] && hi.iter().zip(&bdims).all(|(h, b)| h + 1 == *b) {
        return flood_fill_window(shell, stop);
    }
    let window: [u32; 3] = std::array::from_fn(|a| ((hi[a] + 1) * BRICK).min(dims[a]) - lo[a] * BRICK);
    let by = lo.map(|b| b as i64);
    let (filled, rep) = flood_fill_window(&shell.moved(by.map(|b| -b), window), stop);
    (filled.moved(by, dims), rep)
}

/// [`flood_fill_sparse`] on the whole of `shell`'s grid.
fn flood_fill_window(shell: &SparseBricks, stop: &Stop) -> (SparseBricks, FloodReport) {
    let dims = shell.dims();
    let [nx, ny, nz] = dims;
    let bz = nz.div_ceil(BRICK);
    // Bricks of the layers `layers`, in key order (whole-grid coordinates).
    let bricks_of = |layers: std::ops::Range<u32>| {
        let mut v = Vec::new();
        shell.for_each_brick_in_layers(layers, |b, bits| v.push((b, *bits)));
        v
    };
    // The set runs of plane k and the unset runs of planes (k − 1, k) or (k).
    let window = |bricks: &[([u32; 3], Brick)], k: u32| {
        let planes = k.saturating_sub(1)..k + 1;
        (Runs::of_bricks(nx, ny, k..k + 1, bricks), Runs::of_bricks(nx, ny, planes, bricks).complement())
    };
    let plane_rows = |k: u32| if k > 0 { ny as usize..2 * ny as usize } else { 0..ny as usize };
    // Pass 1: components and which touch the boundary.
    let mut comps = StreamedComponents::new(Connectivity::Six);
    let mut outside: Vec<bool> = Vec::new();
    let mut bases = Vec::with_capacity(nz as usize);
    for layer in (0..bz).take_while(|_| !stop.requested()) {
        let bricks = bricks_of(layer.saturating_sub(1)..layer + 1);
        for k in layer * BRICK..((layer + 1) * BRICK).min(nz) {
            let (_, unset) = window(&bricks, k);
            bases.push(comps.labels() as u32);
            let ids = comps.add(&unset, k > 0);
            outside.resize(comps.labels(), false);
            for r in plane_rows(k) {
                let j = (r % ny as usize) as u32;
                let edge_row = j == 0 || k == 0 || j == ny - 1 || k == nz - 1;
                for a in unset.row_runs(r) {
                    if edge_row || unset.start[a] == 0 || unset.end[a] == nx - 1 {
                        outside[ids[a] as usize] = true;
                    }
                }
            }
        }
    }
    let mut root_outside = vec![false; comps.labels()];
    let roots: Vec<u32> = (0..comps.labels() as u32).map(|id| comps.root(id) as u32).collect();
    for (id, &o) in outside.iter().enumerate() {
        if o {
            root_outside[roots[id] as usize] = true;
        }
    }
    drop(outside);
    // Pass 2, brick layers in parallel: the same labels again, the shell's
    // runs and the enclosed unset runs of each row, as brick rows.
    let by = ny.div_ceil(BRICK);
    let layers: Vec<(Vec<BrickRow>, u64)> = (0..bz)
        .into_par_iter()
        .filter(|_| !stop.requested())
        .map(|layer| {
            let bricks = bricks_of(layer.saturating_sub(1)..layer + 1);
            let mut spans: Vec<[Vec<(u32, u32)>; 64]> = (0..by).map(|_| std::array::from_fn(|_| Vec::new())).collect();
            let mut enclosed = 0u64;
            for k in layer * BRICK..((layer + 1) * BRICK).min(nz) {
                let (set, unset) = window(&bricks, k);
                let (ids, _) = StreamedComponents::relabel(&unset, Connectivity::Six, bases[k as usize]);
                for (n, r) in plane_rows(k).enumerate() {
                    let j = n as u32;
                    let mut row: Vec<(u32, u32)> = set.row_runs(n).map(|a| (set.start[a], set.end[a])).collect();
                    for a in unset.row_runs(r) {
                        if !root_outside[roots[ids[a] as usize] as usize] {
                            row.push((unset.start[a], unset.end[a]));
                            enclosed += (unset.end[a] - unset.start[a] + 1) as u64;
                        }
                    }
                    row.sort_unstable();
                    let out = &mut spans[(j / BRICK) as usize][((k % BRICK) * BRICK + j % BRICK) as usize];
                    for (f, t) in row {
                        push_span(out, f, t);
                    }
                }
            }
            let rows: Vec<BrickRow> = spans.iter().enumerate().map(|(bj, s)| bricks_of_spans(s, dims, bj as u32, layer)).collect();
            (rows, enclosed)
        })
        .collect();
    let enclosed = layers.iter().map(|l| l.1).sum();
    let out = from_brick_rows(dims, layers.into_iter().flat_map(|l| l.0));
    (out, FloodReport { shell: shell.count(), enclosed })
}

/// The voxels of `solid` with a neighbour (6- or 26-connected) outside it
/// or outside the grid.
pub fn hollow(solid: &DenseBits, conn: Connectivity) -> DenseBits {
    let ny = solid.dims()[1];
    let get = |i, j, k| solid.get_signed(i, j, k);
    let mut out = DenseBits::new(solid.dims());
    let wpr = solid.words_per_row();
    out.par_rows_mut().enumerate().for_each(|(r, row)| {
        let (j, k) = ((r % ny as usize) as i64, (r / ny as usize) as i64);
        let words = &solid.words()[r * wpr..(r + 1) * wpr];
        for (wi, &w) in words.iter().enumerate() {
            let mut w = w;
            while w != 0 {
                let b = w.trailing_zeros();
                w &= w - 1;
                let i = (wi as u32 * 64 + b) as i64;
                let skin = match conn {
                    Connectivity::Six => [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
                        .iter()
                        .any(|&(di, dj, dk)| !get(i + di, j + dj, k + dk)),
                    Connectivity::TwentySix => (-1..=1i64)
                        .flat_map(|dk| (-1..=1i64).flat_map(move |dj| (-1..=1i64).map(move |di| (di, dj, dk))))
                        .any(|(di, dj, dk)| !get(i + di, j + dj, k + dk)),
                };
                if skin {
                    DenseBits::fill_row(row, i as u32, i as u32);
                }
            }
        }
    });
    out
}

/// Inclusive intervals `[first, last]` of bricks along `bi`, sorted and
/// disjoint (intersected with [`super::solid::intersect`]).
type Intervals = Vec<(u32, u32)>;

/// Bricks whose neighbours on both sides along `bi` are in the list too.
fn erode(a: &[(u32, u32)]) -> Intervals {
    a.iter().filter(|r| r.1 >= r.0 + 2).map(|r| (r.0 + 1, r.1 - 1)).collect()
}

/// [`hollow`] on sparse bricks: the set voxels of `solid` with a 6- (or
/// 26-) neighbour unset or outside the grid, as sparse bricks.
pub fn hollow_sparse(solid: &SparseBricks, conn: Connectivity) -> SparseBricks {
    let dims = solid.dims();
    let bdims = dims.map(|d| d.div_ceil(BRICK));
    // Rows of full bricks: (bj, bk) -> intervals along bi (touching runs joined).
    let mut rows: HashMap<(u32, u32), Intervals> = HashMap::new();
    for (b, n) in solid.full_runs() {
        let row = rows.entry((b[1], b[2])).or_default();
        match row.last_mut() {
            Some(last) if last.1 + 1 == b[0] => last.1 += n,
            _ => row.push((b[0], b[0] + n - 1)),
        }
    }
    let row = |bj: i64, bk: i64| -> &[(u32, u32)] {
        if bj < 0 || bk < 0 {
            return &[];
        }
        rows.get(&(bj as u32, bk as u32)).map_or(&[], |v| v.as_slice())
    };
    // Full bricks with every needed neighbour full keep nothing; the rest
    // of each row (and every stored brick) is skinned brick by brick.
    let mut work: Vec<[u32; 3]> = solid.stored_bricks().collect();
    for (&(bj, bk), full) in &rows {
        let (j, k) = (bj as i64, bk as i64);
        let deep = match conn {
            Connectivity::Six => {
                [row(j - 1, k), row(j + 1, k), row(j, k - 1), row(j, k + 1)].iter().fold(erode(full), |d, r| super::solid::intersect(&d, r))
            }
            Connectivity::TwentySix => {
                let mut d = erode(full);
                for (dj, dk) in [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)] {
                    d = super::solid::intersect(&d, &erode(row(j + dj, k + dk)));
                }
                d
            }
        };
        let mut d = deep.iter().peekable();
        for &(s, e) in full {
            for bi in s..=e {
                while d.peek().is_some_and(|r| r.1 < bi) {
                    d.next();
                }
                if d.peek().is_none_or(|r| r.0 > bi) {
                    work.push([bi, bj, bk]);
                }
            }
        }
    }
    let skins: Vec<([u32; 3], Brick)> = work
        .par_iter()
        .filter_map(|&b| {
            let skin = skin_of(solid, b, bdims, conn);
            (skin != [0; 8]).then_some((b, skin))
        })
        .collect();
    SparseBricks::from_parts(dims, skins, Vec::new())
}

/// The skin of brick `b`: its set voxels with a neighbour unset, from the
/// brick and its neighbours (6 or 26) on a 10×10×10 halo of bits (rows
/// along x as `u16`, bit `x + 1`; bricks outside the grid are empty).
fn skin_of(solid: &SparseBricks, b: [u32; 3], bdims: [u32; 3], conn: Connectivity) -> Brick {
    let mut h = [[0u16; 10]; 10]; // [z + 1][y + 1]
    let six = conn == Connectivity::Six;
    for dz in -1i64..=1 {
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let faces = (dx != 0) as u8 + (dy != 0) as u8 + (dz != 0) as u8;
                if six && faces > 1 {
                    continue;
                }
                let nb = [b[0] as i64 + dx, b[1] as i64 + dy, b[2] as i64 + dz];
                if (0..3).any(|a| nb[a] < 0 || nb[a] >= bdims[a] as i64) {
                    continue;
                }
                let bits = solid.brick_bits(nb.map(|c| c as u32));
                if bits == [0; 8] {
                    continue;
                }
                // The neighbour's voxels that fall in the halo: its layers
                // (rows) `s` go to halo layers (rows) `s + d * 8 + 1`.
                let span = |d: i64| match d {
                    -1 => 7..8,
                    1 => 0..1,
                    _ => 0..8,
                };
                let at = |v: usize, d: i64| (v as i64 + d * 8 + 1) as usize;
                for z in span(dz) {
                    for y in span(dy) {
                        let r = ((bits[z] >> (y * 8)) & 0xff) as u16;
                        h[at(z, dz)][at(y, dy)] |= match dx {
                            -1 => r >> 7,
                            1 => (r & 1) << 9,
                            _ => r << 1,
                        };
                    }
                }
            }
        }
    }
    let mut out = [0u64; 8];
    for z in 0..8 {
        for y in 0..8 {
            let c = h[z + 1][y + 1];
            if c & 0x1fe == 0 {
                continue;
            }
            let inner = match conn {
                Connectivity::Six => c & (c << 1) & (c >> 1) & h[z + 1][y] & h[z + 1][y + 2] & h[z][y + 1] & h[z + 2][y + 1],
                Connectivity::TwentySix => {
                    let mut a = u16::MAX;
                    for r in [&h[z], &h[z + 1], &h[z + 2]] {
                        for &v in &r[y..y + 3] {
                            a &= v & (v << 1) & (v >> 1);
                        }
                    }
                    a
                }
            };
            let skin = (c & !inner) >> 1 & 0xff;
            out[z] |= (skin as u64) << (y * 8);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shell_box(n: u32, lo: u32, hi: u32) -> DenseBits {
        let mut b = DenseBits::new([n, n, n]);
        for k in lo..=hi {
            for j in lo..=hi {
                for i in lo..=hi {
                    if [i, j, k].iter().any(|&c| c == lo || c == hi) {
                        b.set(i, j, k);
                    }
                }
            }
        }
        b
    }

    #[test]
    fn a_closed_shell_fills_and_a_holed_one_leaks() {
        let s = shell_box(10, 2, 7);
        let (f, rep) = flood_fill(&s);
        assert_eq!(f.count(), 216);
        assert_eq!(rep.enclosed, 64);
        let mut holed = s.clone();
        let mut h = DenseBits::new(holed.dims());
        holed.for_each_set(|i, j, k| {
            if (i, j, k) != (4, 4, 7) {
                h.set(i, j, k);
            }
        });
        holed = h;
        let (f, rep) = flood_fill(&holed);
        assert_eq!(rep.enclosed, 0);
        assert_eq!(f.count(), holed.count());
    }

    #[test]
    fn hollow_keeps_the_skin() {
        let (solid, _) = flood_fill(&shell_box(10, 2, 7));
        assert_eq!(hollow(&solid, Connectivity::Six).count(), 216 - 64);
        assert_eq!(hollow(&solid, Connectivity::TwentySix).count(), 216 - 64);
        // A solid touching the grid's faces keeps them as skin.
        let mut full = DenseBits::new([3, 3, 3]);
        for row in full.rows_mut() {
            DenseBits::fill_row(row, 0, 2);
        }
        assert_eq!(hollow(&full, Connectivity::Six).count(), 26);
    }

    /// Sparse bricks of `d`, full bricks as runs (as a sparse solid has them).
    fn sparse_of(d: &DenseBits) -> SparseBricks {
        let mut bricks = Vec::new();
        crate::VoxelSource::for_each_brick(d, &mut |b, bits| bricks.push((b, *bits)));
        SparseBricks::from_parts(d.dims(), bricks, Vec::new())
    }

    /// The sparse hollow equals the dense one, for both connectivities, on
    /// boxes across brick and grid borders, a ball, and random unions of
    /// boxes (with interiors deep enough for bricks to be skipped).
    #[test]
    fn sparse_hollow_equals_dense() {
        let mut shapes: Vec<DenseBits> = Vec::new();
        let dims = [70, 45, 52];
        let boxed = |lo: [u32; 3], hi: [u32; 3]| {
            let mut d = DenseBits::new(dims);
            d.fill_box(lo, hi);
            d
        };
        shapes.push(boxed([0, 0, 0], [69, 44, 51]));
        shapes.push(boxed([3, 8, 7], [60, 40, 47]));
        shapes.push(boxed([8, 8, 8], [39, 39, 39]));
        let mut ball = DenseBits::new(dims);
        for k in 0..52u32 {
            for j in 0..45u32 {
                for i in 0..70u32 {
                    let (x, y, z) = (i as f64 - 33.3, j as f64 - 22.1, k as f64 - 25.7);
                    if x * x + y * y + z * z < 21.5 * 21.5 {
                        ball.set(i, j, k);
                    }
                }
            }
        }
        shapes.push(ball);
        let mut state = 99u64;
        let mut next = |n: u32| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 33) % n as u64) as u32
        };
        for _ in 0..4 {
            let mut d = DenseBits::new(dims);
            for _ in 0..5 {
                let lo = [next(50), next(30), next(35)];
                let hi = [lo[0] + 5 + next(20), lo[1] + 3 + next(14), lo[2] + 4 + next(16)];
                d.fill_box(lo, [hi[0].min(69), hi[1].min(44), hi[2].min(51)]);
            }
            shapes.push(d);
        }
        for (n, d) in shapes.iter().enumerate() {
            let sparse = sparse_of(d);
            assert_eq!(sparse.to_dense(), *d);
            for conn in [Connectivity::Six, Connectivity::TwentySix] {
                let want = hollow(d, conn);
                let got = hollow_sparse(&sparse, conn);
                if let Some(v) = want.first_difference(&got.to_dense()) {
                    panic!("shape {n} {conn:?}: differs at {v:?} (dense {})", want.get(v[0], v[1], v[2]));
                }
                assert_eq!(got.full_bricks(), 0);
            }
        }
        assert!(sparse_of(&shapes[1]).full_bricks() > 20, "the big box has deep full bricks");
    }
}
