//! A signed (or unsigned) distance field as the writers take it: the band's
//! values with their signs, the inside voxels, and the background value
//! everything else holds (OpenVDB's level-set convention: `+background`
//! outside, `−background` inside).

use rayon::prelude::*;

use super::band::Band;
use crate::grid::brick::Brick;
use crate::grid::sparse::SparseBricks;
use crate::VoxelSource;

/// A distance field: `band` holds the stored voxels (the narrow band, or
/// every voxel) with signed values; every other voxel holds
/// `−background` when `inside` holds it, else `+background`.
#[derive(Clone, Debug)]
pub struct Field {
    /// The stored voxels and their values (negative inside).
    pub band: Band,
    /// The inside voxels, as the sparse solid gives them (`None`: unsigned,
    /// nothing is inside).
    pub inside: Option<SparseBricks>,
    /// The value of the voxels outside the band, by its sign.
    pub background: f32,
}

/// The value an inside voxel at distance `d` stores: `−d`, and for a
/// centre on the surface the float just below zero, so `value < 0` holds
/// on exactly the inside voxels.
#[inline]
pub fn inside_value(d: f32) -> f32 {
    if d > 0.0 {
        -d
    } else {
        -f32::from_bits(1)
    }
}

impl Field {
    /// The field from unsigned `band` values: the band voxels `inside`
    /// holds are made negative ([`inside_value`]).
    pub fn signed(mut band: Band, inside: Option<SparseBricks>, background: f32) -> Field {
        if let Some(ins) = &inside {
            // Each brick's values, split off in place (bricks are in value order).
            let ends: Vec<usize> = band.bricks.iter().skip(1).map(|b| b.first).chain([band.values.len()]).collect();
            let mut chunks: Vec<&mut [f32]> = Vec::with_capacity(band.bricks.len());
            let mut rest = band.values.as_mut_slice();
            for (b, &end) in band.bricks.iter().zip(&ends) {
                let (head, tail) = rest.split_at_mut(end - b.first);
                chunks.push(head);
                rest = tail;
            }
            chunks.into_par_iter().zip(band.bricks.par_iter()).for_each(|(vals, b)| {
                let bits = ins.brick_bits(b.at);
                let mut n = 0;
                for (z, &w) in b.mask.iter().enumerate() {
                    let mut w = w;
                    while w != 0 {
                        let bit = w.trailing_zeros();
                        w &= w - 1;
                        if bits[z] >> bit & 1 == 1 {
                            vals[n] = inside_value(vals[n]);
                        }
                        n += 1;
                    }
                }
            });
        }
        Field { band, inside, background }
    }

    /// Voxels along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.band.dims
    }

    /// The value of every voxel of brick `at`, in slot order
    /// (`z·64 + y·8 + x`, the bit order of [`Brick`]), and which are stored.
    pub fn brick_values(&self, at: [u32; 3]) -> ([f32; 512], Brick) {
        let inside = self.inside.as_ref().map_or([0; 8], |i| i.brick_bits(at));
        let mut out = [0f32; 512];
        for (s, v) in out.iter_mut().enumerate() {
            *v = if inside[s >> 6] >> (s & 63) & 1 == 1 { -self.background } else { self.background };
        }
        let Some((b, vals)) = self.band.brick(at) else { return (out, [0; 8]) };
        let mut vals = vals.iter();
        for (z, &w) in b.mask.iter().enumerate() {
            let mut w = w;
            while w != 0 {
                let bit = w.trailing_zeros() as usize;
                w &= w - 1;
                out[z * 64 + bit] = *vals.next().expect("one value per band voxel");
            }
        }
        (out, b.mask)
    }

    /// Every voxel's value in C order (`[i][j][k]`, `k` fastest, the
    /// layout of `.npy`): 4 bytes per voxel of the grid.
    pub fn dense(&self) -> Vec<f32> {
        let [nx, ny, nz] = self.dims().map(|d| d as usize);
        let mut out = vec![self.background; nx * ny * nz];
        if let Some(ins) = &self.inside {
            let bg = -self.background;
            ins.for_each_set(&mut |i, j, k| out[(i as usize * ny + j as usize) * nz + k as usize] = bg);
        }
        self.band.for_each(|i, j, k, v| out[(i as usize * ny + j as usize) * nz + k as usize] = v);
        out
    }
}
