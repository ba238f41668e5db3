//! The scene partition of seed 002 (§ "partition de la scène"): a regular
//! 8×8×8 grid over the triangle centroids; each non-empty cell's triangles
//! form a cluster, drawn by one indirect command, the whole scene by one
//! `multi_draw_indexed_indirect` call over an index buffer ordered by
//! cluster.
//!
//! Cell of a triangle with centroid `c`, per axis:
//! `min(7, floor(8 · (c − lo) / (hi − lo)))`, `lo`/`hi` the bounding box of
//! all centroids (an axis where `hi = lo` puts everything in cell 0). A
//! cluster's box is the bounding box of its triangles' vertices (so it
//! contains them, not only their centroids).

use glam::Vec3;

use crate::scene::Scene;

/// Cells per axis.
pub const CELLS: usize = 8;

/// One cluster: a contiguous range of the index buffer and its box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cluster {
    /// First index in [`Partition::indices`].
    pub first_index: u32,
    /// Indices (three per triangle).
    pub index_count: u32,
    /// Box corners containing every vertex of the cluster.
    pub lo: Vec3,
    /// Upper corner.
    pub hi: Vec3,
    /// The cell, `x + 8 (y + 8 z)`.
    pub cell: u32,
}

/// The clusters in cell order and the index buffer they cut.
#[derive(Clone, Debug, Default)]
pub struct Partition {
    /// Non-empty cells' clusters, by cell index.
    pub clusters: Vec<Cluster>,
    /// Vertex indices, ordered by cluster (each triangle's three in order).
    pub indices: Vec<u32>,
}

/// The cell of a centroid `c` given the centroids' box.
pub fn cell_of(c: Vec3, lo: Vec3, hi: Vec3) -> [usize; 3] {
    std::array::from_fn(|a| {
        let ext = hi[a] - lo[a];
        if ext.is_nan() || ext <= 0.0 {
            return 0;
        }
        let f = (CELLS as f32 * (c[a] - lo[a]) / ext).floor();
        (f.max(0.0) as usize).min(CELLS - 1)
    })
}

impl Partition {
    /// Partitions the scene's triangles.
    pub fn new(scene: &Scene) -> Partition {
        let n = scene.triangles();
        let tri = |t: usize| [0, 1, 2].map(|c| Vec3::from(scene.vertices[3 * t + c].position));
        let centroids: Vec<Vec3> = (0..n).map(|t| tri(t).iter().sum::<Vec3>() / 3.0).collect();
        let Some(first) = centroids.first() else { return Partition::default() };
        let (lo, hi) = centroids.iter().fold((*first, *first), |(lo, hi), c| (lo.min(*c), hi.max(*c)));
        let cells: Vec<u32> = centroids
            .iter()
            .map(|&c| {
                let [x, y, z] = cell_of(c, lo, hi);
                (x + CELLS * (y + CELLS * z)) as u32
            })
            .collect();
        // Counting sort by cell keeps triangles of a cell in scene order.
        let mut start = vec![0u32; CELLS * CELLS * CELLS + 1];
        for &c in &cells {
            start[c as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut order = vec![0u32; n];
        let mut next = start.clone();
        for (t, &c) in cells.iter().enumerate() {
            order[next[c as usize] as usize] = t as u32;
            next[c as usize] += 1;
        }
        let mut out = Partition { clusters: Vec::new(), indices: Vec::with_capacity(3 * n) };
        for cell in 0..CELLS * CELLS * CELLS {
            let (s, e) = (start[cell] as usize, start[cell + 1] as usize);
            if s == e {
                continue;
            }
            let first_index = out.indices.len() as u32;
            let (mut blo, mut bhi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for &t in &order[s..e] {
                for (c, p) in tri(t as usize).into_iter().enumerate() {
                    blo = blo.min(p);
                    bhi = bhi.max(p);
                    out.indices.push(3 * t + c as u32);
                }
            }
            out.clusters.push(Cluster {
                first_index,
                index_count: out.indices.len() as u32 - first_index,
                lo: blo,
                hi: bhi,
                cell: cell as u32,
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ShadeMaterial;

    #[test]
    fn every_triangle_in_one_cluster_whose_box_holds_it() {
        let mut scene = Scene::default();
        let m = scene.add_material(ShadeMaterial::new([1.0; 3], [0.0; 3], 0.5));
        let mut state = 7u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 10.0
        };
        for _ in 0..500 {
            let a = Vec3::new(rnd(), rnd(), rnd() * 0.1);
            scene.push_triangle([a, a + Vec3::new(rnd() * 0.1, 0.0, 0.0), a + Vec3::new(0.0, rnd() * 0.1, 0.01)], m);
        }
        let p = Partition::new(&scene);
        let mut seen = vec![0; scene.triangles()];
        for c in &p.clusters {
            assert!(c.index_count > 0 && c.index_count % 3 == 0);
            for &i in &p.indices[c.first_index as usize..(c.first_index + c.index_count) as usize] {
                let v = Vec3::from(scene.vertices[i as usize].position);
                assert!(v.cmpge(c.lo).all() && v.cmple(c.hi).all());
                if i % 3 == 0 {
                    seen[i as usize / 3] += 1;
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
        assert!(p.clusters.windows(2).all(|w| w[0].cell < w[1].cell));
        assert!(p.clusters.len() > 8 && p.clusters.len() <= 512);
    }

    #[test]
    fn cells_follow_the_formula() {
        let (lo, hi) = (Vec3::ZERO, Vec3::new(8.0, 16.0, 0.0));
        assert_eq!(cell_of(Vec3::new(0.0, 0.0, 0.0), lo, hi), [0, 0, 0]);
        assert_eq!(cell_of(Vec3::new(8.0, 16.0, 0.0), lo, hi), [7, 7, 0]);
        assert_eq!(cell_of(Vec3::new(2.5, 4.0, 0.0), lo, hi), [2, 2, 0]);
    }
}
