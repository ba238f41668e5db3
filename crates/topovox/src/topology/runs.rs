//! Runs of equal voxels along `i`, and connected components over them.
//!
//! A grid's set (or unset) voxels are stored per row `(j, k)` as maximal
//! runs `[start, end]` along `i`. Two runs in neighbouring rows are
//! 6-adjacent iff they share an `i`; 26-adjacent iff their `i` ranges come
//! within one of each other (and the rows differ by at most one in `j` and
//! `k`). Union–find over runs labels components with work proportional to
//! the number of runs, not voxels, so a 1024³ grid is a few million runs.

use rayon::prelude::*;

use crate::grid::bricks::{Brick, BRICK};
use crate::grid::dense::DenseBits;

/// Connectivity of a path of voxels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Connectivity {
    /// Through faces.
    Six,
    /// Through faces, edges or corners.
    TwentySix,
}

/// The maximal runs of set (or unset) voxels of a grid, per row.
#[derive(Clone, Debug)]
pub struct Runs {
    dims: [u32; 3],
    /// `row_start[r]..row_start[r+1]` are the runs of row `r = k·ny + j`.
    pub row_start: Vec<u32>,
    /// First voxel of each run.
    pub start: Vec<u32>,
    /// Last voxel of each run (inclusive).
    pub end: Vec<u32>,
}

impl Runs {
    /// The runs of voxels equal to `value` in `bits`.
    pub fn of(bits: &DenseBits, value: bool) -> Runs {
        Runs::of_planes(bits, value, 0..bits.dims()[2])
    }

    /// The runs of voxels equal to `value` in the planes `planes` of
    /// `bits`, as a grid of those planes (row `r` is `(k − planes.start)·ny + j`).
    pub fn of_planes(bits: &DenseBits, value: bool, planes: std::ops::Range<u32>) -> Runs {
        let [nx, ny, _] = bits.dims();
        let dims = [nx, ny, planes.len() as u32];
        let wpr = bits.words_per_row();
        let plane_words = wpr * ny as usize;
        let words = &bits.words()[planes.start as usize * plane_words..planes.end as usize * plane_words];
        let per_row: Vec<Vec<(u32, u32)>> = words
            .par_chunks(wpr.max(1))
            .map(|row| {
                let mut out = Vec::new();
                let mut open: Option<u32> = None;
                for (wi, &w) in row.iter().enumerate() {
                    let w = if value { w } else { !w };
                    let base = wi as u32 * 64;
                    if (w == 0 && open.is_none()) || (w == u64::MAX && open.is_some()) {
                        continue;
                    }
                    for b in 0..64u32 {
                        let i = base + b;
                        if i >= nx {
                            break;
                        }
                        let on = (w >> b) & 1 == 1;
                        match (on, open) {
                            (true, None) => open = Some(i),
                            (false, Some(s)) => {
                                out.push((s, i - 1));
                                open = None;
                            }
                            _ => {}
                        }
                    }
                }
                if let Some(s) = open {
                    out.push((s, nx - 1));
                }
                out
            })
            .collect();
        // Rows of zero words: no chunks at all when nx is 0.
        let per_row = if wpr == 0 { vec![Vec::new(); ny as usize * planes.len()] } else { per_row };
        let total: usize = per_row.iter().map(Vec::len).sum();
        let mut row_start = Vec::with_capacity(per_row.len() + 1);
        let mut start = Vec::with_capacity(total);
        let mut end = Vec::with_capacity(total);
        row_start.push(0);
        for r in per_row {
            for (s, e) in r {
                start.push(s);
                end.push(e);
            }
            row_start.push(start.len() as u32);
        }
        Runs { dims, row_start, start, end }
    }

    /// The runs of the set voxels of sparse bricks: `bricks` (whole-grid
    /// brick coordinates, sorted by `(bk, bj, bi)`, full bricks included)
    /// hold every set voxel of the planes `planes` of an `nx × ny` grid;
    /// bricks outside those planes are skipped. Rows as in [`Runs::of_planes`].
    pub fn of_bricks(nx: u32, ny: u32, planes: std::ops::Range<u32>, bricks: &[([u32; 3], Brick)]) -> Runs {
        let mut row_start = Vec::with_capacity(ny as usize * planes.len() + 1);
        let (mut start, mut end) = (Vec::new(), Vec::new());
        row_start.push(0u32);
        for k in planes.clone() {
            let (bk, z) = (k / BRICK, (k % BRICK) as usize);
            let (mut g, layer_end) = (bricks.partition_point(|(b, _)| b[2] < bk), bricks.partition_point(|(b, _)| b[2] <= bk));
            let mut j = 0;
            while g < layer_end {
                // The bricks of brick row bj, sorted by bi.
                let bj = bricks[g].0[1];
                let row_end = g + bricks[g..layer_end].partition_point(|(b, _)| b[1] == bj);
                while j < bj * BRICK {
                    row_start.push(start.len() as u32);
                    j += 1;
                }
                while j < ((bj + 1) * BRICK).min(ny) {
                    let y = (j % BRICK) * 8;
                    let mut open: Option<(u32, u32)> = None;
                    for (b, bits) in &bricks[g..row_end] {
                        let mut byte = (bits[z] >> y) as u8 as u32;
                        let i0 = b[0] * BRICK;
                        while byte != 0 {
                            let s = byte.trailing_zeros();
                            let len = (byte >> s).trailing_ones();
                            let (first, last) = (i0 + s, i0 + s + len - 1);
                            match open {
                                Some((os, oe)) if oe + 1 == first => open = Some((os, last)),
                                _ => {
                                    if let Some((os, oe)) = open {
                                        start.push(os);
                                        end.push(oe);
                                    }
                                    open = Some((first, last));
                                }
                            }
                            byte &= !((1u32 << (s + len)) - 1);
                        }
                    }
                    if let Some((os, oe)) = open {
                        start.push(os);
                        end.push(oe);
                    }
                    row_start.push(start.len() as u32);
                    j += 1;
                }
                g = row_end;
            }
            while j < ny {
                row_start.push(start.len() as u32);
                j += 1;
            }
        }
        Runs { dims: [nx, ny, planes.len() as u32], row_start, start, end }
    }

    /// The runs of the other voxels: each row's complement within `0..nx`.
    pub fn complement(&self) -> Runs {
        let nx = self.dims[0];
        let rows = self.row_start.len() - 1;
        let mut row_start = Vec::with_capacity(rows + 1);
        let (mut start, mut end) = (Vec::with_capacity(self.len() + rows), Vec::with_capacity(self.len() + rows));
        row_start.push(0u32);
        for r in 0..rows {
            let mut next = 0u32;
            for a in self.row_runs(r) {
                if self.start[a] > next {
                    start.push(next);
                    end.push(self.start[a] - 1);
                }
                next = self.end[a] + 1;
            }
            if next < nx {
                start.push(next);
                end.push(nx - 1);
            }
            row_start.push(start.len() as u32);
        }
        Runs { dims: self.dims, row_start, start, end }
    }

    /// Voxels along x, y and the planes the runs cover.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.start.len()
    }

    /// No runs at all.
    pub fn is_empty(&self) -> bool {
        self.start.is_empty()
    }

    /// Row index of `(j, k)`.
    #[inline]
    pub fn row(&self, j: u32, k: u32) -> usize {
        k as usize * self.dims[1] as usize + j as usize
    }

    /// The runs of a row, as a range of run indices.
    #[inline]
    pub fn row_runs(&self, r: usize) -> std::ops::Range<usize> {
        self.row_start[r] as usize..self.row_start[r + 1] as usize
    }

    /// `(j, k)` of row `r`.
    #[inline]
    pub fn row_jk(&self, r: usize) -> (u32, u32) {
        ((r % self.dims[1] as usize) as u32, (r / self.dims[1] as usize) as u32)
    }

    /// The run of row `(j, k)` containing `i`, if any.
    pub fn find(&self, i: u32, j: u32, k: u32) -> Option<usize> {
        let range = self.row_runs(self.row(j, k));
        let ends = &self.end[range.clone()];
        let p = ends.partition_point(|&e| e < i);
        let idx = range.start + p;
        (p < ends.len() && self.start[idx] <= i).then_some(idx)
    }

    /// Calls `f(a, b)` for every pair of adjacent runs with `a` in a row
    /// after `b`'s (each pair once).
    pub fn for_each_adjacent(&self, conn: Connectivity, mut f: impl FnMut(usize, usize)) {
        let [_, ny, nz] = self.dims;
        let grow = if conn == Connectivity::Six { 0 } else { 1 };
        for k in 0..nz {
            for j in 0..ny {
                let r = self.row(j, k);
                if self.row_start[r] == self.row_start[r + 1] {
                    continue;
                }
                for (dj, dk) in previous_rows(conn) {
                    let (jj, kk) = (j as i64 + dj, k as i64 + dk);
                    if jj < 0 || kk < 0 || jj >= ny as i64 {
                        continue;
                    }
                    let q = self.row(jj as u32, kk as u32);
                    // Two-pointer sweep over the sorted runs of both rows.
                    let (ra, rb) = (self.row_runs(r), self.row_runs(q));
                    let (mut a, mut b) = (ra.start, rb.start);
                    while a < ra.end && b < rb.end {
                        let (s1, e1) = (self.start[a] as i64, self.end[a] as i64 + grow);
                        let (s2, e2) = (self.start[b] as i64, self.end[b] as i64);
                        if s1 - grow <= e2 && s2 <= e1 {
                            f(a, b);
                        }
                        if e1 - grow < e2 {
                            a += 1;
                        } else {
                            b += 1;
                        }
                    }
                }
            }
        }
    }

    /// Runs adjacent to run `a` (in any neighbouring row), for path searches.
    pub fn neighbours(&self, a: usize, r: usize, conn: Connectivity, out: &mut Vec<usize>) {
        out.clear();
        let [_, ny, nz] = self.dims;
        let (j, k) = self.row_jk(r);
        let grow = if conn == Connectivity::Six { 0 } else { 1 };
        let (s1, e1) = (self.start[a] as i64 - grow, self.end[a] as i64 + grow);
        for (dj, dk) in all_rows(conn) {
            let (jj, kk) = (j as i64 + dj, k as i64 + dk);
            if jj < 0 || kk < 0 || jj >= ny as i64 || kk >= nz as i64 {
                continue;
            }
            let q = self.row(jj as u32, kk as u32);
            for b in self.row_runs(q) {
                if self.start[b] as i64 <= e1 && self.end[b] as i64 >= s1 {
                    out.push(b);
                }
            }
        }
    }
}

fn previous_rows(conn: Connectivity) -> &'static [(i64, i64)] {
    match conn {
        Connectivity::Six => &[(-1, 0), (0, -1)],
        Connectivity::TwentySix => &[(-1, 0), (-1, -1), (0, -1), (1, -1)],
    }
}

fn all_rows(conn: Connectivity) -> &'static [(i64, i64)] {
    match conn {
        Connectivity::Six => &[(-1, 0), (1, 0), (0, -1), (0, 1)],
        Connectivity::TwentySix => &[(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)],
    }
}

/// Union–find with path halving and union by index (deterministic).
#[derive(Clone, Debug)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> UnionFind {
        UnionFind { parent: (0..n as u32).collect() }
    }

    /// The representative of `x`.
    pub fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            let g = self.parent[self.parent[x] as usize];
            self.parent[x] = g;
            x = g as usize;
        }
        x
    }

    /// Merges the sets of `a` and `b`; the smaller representative wins.
    /// Returns whether they were two sets.
    pub fn union(&mut self, a: usize, b: usize) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi] = lo as u32;
        }
        ra != rb
    }

    /// Adds a singleton; returns it.
    pub fn push(&mut self) -> usize {
        self.parent.push(self.parent.len() as u32);
        self.parent.len() - 1
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.parent.len()
    }

    /// No elements.
    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }
}

/// Components counted window by window (grids past memory): each
/// window's runs (its own planes and the last plane of the window before)
/// are joined locally, every local component gets a global label, and the
/// runs of the shared plane join the labels they had in the window before.
#[derive(Clone, Debug)]
pub struct StreamedComponents {
    conn: Connectivity,
    labels: UnionFind,
    merged: usize,
    /// Global label of each run of the last plane seen.
    carry: Vec<u32>,
}

impl StreamedComponents {
    /// No windows yet.
    pub fn new(conn: Connectivity) -> StreamedComponents {
        StreamedComponents { conn, labels: UnionFind::new(0), merged: 0, carry: Vec::new() }
    }

    /// Adds the runs of a window; with `shared`, their first plane is the
    /// last plane of the previous window. Returns every run's global label
    /// (the labels [`StreamedComponents::relabel`] gives again from the
    /// same runs and the number of labels before this window).
    pub fn add(&mut self, runs: &Runs, shared: bool) -> Vec<u32> {
        let (ids, new) = Self::relabel(runs, self.conn, self.labels.len() as u32);
        for _ in 0..new {
            self.labels.push();
        }
        let ny = runs.dims()[1] as usize;
        if runs.dims()[2] == 0 {
            return ids;
        }
        if shared {
            let first = runs.row_start[ny] as usize;
            debug_assert_eq!(first, self.carry.len());
            for (t, &c) in self.carry.iter().enumerate().take(first) {
                if self.labels.union(ids[t] as usize, c as usize) {
                    self.merged += 1;
                }
            }
        }
        let last = runs.row_start[runs.row_start.len() - 1 - ny] as usize;
        self.carry = ids[last..].to_vec();
        ids
    }

    /// Adds a window without set voxels: no labels, and nothing of its
    /// last plane to join with the next window's first.
    pub fn add_empty(&mut self) {
        self.carry.clear();
    }

    /// The global labels [`StreamedComponents::add`] gave `runs` when
    /// `base` labels existed before them, and how many it added: local
    /// components numbered from `base` in order of their first run.
    pub fn relabel(runs: &Runs, conn: Connectivity, base: u32) -> (Vec<u32>, usize) {
        let mut local = UnionFind::new(runs.len());
        runs.for_each_adjacent(conn, |a, b| {
            local.union(a, b);
        });
        // Union by index: a run's representative comes no later than it.
        let mut ids = vec![0u32; runs.len()];
        let mut new = 0;
        for x in 0..runs.len() {
            let r = local.find(x);
            ids[x] = if r == x {
                new += 1;
                base + new as u32 - 1
            } else {
                ids[r]
            };
        }
        (ids, new)
    }

    /// Labels given so far.
    pub fn labels(&self) -> usize {
        self.labels.len()
    }

    /// The representative of global label `id`.
    pub fn root(&mut self, id: u32) -> usize {
        self.labels.find(id as usize)
    }

    /// Components of all windows added.
    pub fn count(&self) -> usize {
        self.labels.len() - self.merged
    }
}

/// Component label (the smallest run index in it) of every run, and the
/// number of components.
pub fn components(runs: &Runs, conn: Connectivity) -> (Vec<u32>, usize) {
    let mut uf = UnionFind::new(runs.len());
    runs.for_each_adjacent(conn, |a, b| {
        uf.union(a, b);
    });
    let mut count = 0;
    let labels = (0..runs.len())
        .map(|x| {
            let r = uf.find(x);
            if r == x {
                count += 1;
            }
            r as u32
        })
        .collect();
    (labels, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(dims: [u32; 3], set: &[[u32; 3]]) -> DenseBits {
        let mut b = DenseBits::new(dims);
        for v in set {
            b.set(v[0], v[1], v[2]);
        }
        b
    }

    #[test]
    fn diagonal_voxels_are_26_but_not_6_connected() {
        let b = grid([4, 4, 4], &[[0, 0, 0], [1, 1, 1], [2, 2, 1]]);
        let r = Runs::of(&b, true);
        assert_eq!(components(&r, Connectivity::Six).1, 3);
        assert_eq!(components(&r, Connectivity::TwentySix).1, 1);
    }

    #[test]
    fn runs_cross_word_boundaries() {
        let mut b = DenseBits::new([130, 1, 1]);
        for i in 60..=70 {
            b.set(i, 0, 0);
        }
        b.set(129, 0, 0);
        let set = Runs::of(&b, true);
        assert_eq!((set.start.clone(), set.end.clone()), (vec![60, 129], vec![70, 129]));
        let unset = Runs::of(&b, false);
        assert_eq!((unset.start.clone(), unset.end.clone()), (vec![0, 71], vec![59, 128]));
        assert_eq!(unset.find(100, 0, 0), Some(1));
        assert_eq!(unset.find(65, 0, 0), None);
    }

    #[test]
    fn a_closed_shell_splits_the_unset_voxels_in_two() {
        let mut b = DenseBits::new([5, 5, 5]);
        for k in 1..4 {
            for j in 1..4 {
                for i in 1..4 {
                    if (i, j, k) != (2, 2, 2) {
                        b.set(i, j, k);
                    }
                }
            }
        }
        let r = Runs::of(&b, false);
        assert_eq!(components(&r, Connectivity::TwentySix).1, 2);
        assert_eq!(components(&r, Connectivity::Six).1, 2);
    }
}
