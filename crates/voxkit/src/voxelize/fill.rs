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
//! as for Minecraft-style builds.

use rayon::prelude::*;

use crate::grid::dense::DenseBits;
use crate::topology::runs::{components, Connectivity, Runs};

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
}
