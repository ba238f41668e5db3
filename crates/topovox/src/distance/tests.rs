//! Every distance path against the brute-force reference, on random
//! soups with degenerate triangles, segments and points; the paths
//! against each other bit for bit, at every thread count.

use glam::DVec3;

use super::{band, nearest, reference, DistanceError, Pieces};
use crate::stop::Stop;
use crate::test_rng::Xorshift;
use crate::{GridSpec, Mesh};

/// A soup of `n` triangles in `[0, 10]³`: random ones, slivers, triangles
/// with two equal corners, and a few segments.
fn soup(rng: &mut Xorshift, n: usize) -> Mesh {
    let mut m = Mesh::default();
    let point = |rng: &mut Xorshift| DVec3::new(rng.below(10_001) as f64, rng.below(10_001) as f64, rng.below(10_001) as f64) * 1e-3;
    for t in 0..n {
        let a = point(rng);
        let b = if t % 7 == 3 { a } else { a + (point(rng) - DVec3::splat(5.0)) * 0.4 };
        let c = if t % 5 == 1 { a + (b - a) * 0.5 } else { a + (point(rng) - DVec3::splat(5.0)) * 0.4 };
        let base = m.positions.len() as u32;
        m.positions.extend([a, b, c]);
        m.triangles.push([base, base + 1, base + 2]);
    }
    for _ in 0..3 {
        let base = m.positions.len() as u32;
        let a = point(rng);
        m.positions.extend([a, a + DVec3::new(1.5, -0.5, 0.25)]);
        m.segments.push([base, base + 1]);
    }
    m
}

/// Cubes, or every other time boxes whose edges differ up to 1:8.
fn grid(rng: &mut Xorshift) -> GridSpec {
    let h = 0.35 + rng.below(1000) as f64 * 4e-4;
    let o = DVec3::new(rng.signed(1000) as f64, rng.signed(1000) as f64, rng.signed(1000) as f64) * 1e-3 - DVec3::splat(0.5);
    if rng.below(2) == 0 {
        return GridSpec::new(o, h, [26 + rng.below(6), 24 + rng.below(6), 28]).unwrap();
    }
    let s = DVec3::new(h / (1 + rng.below(8)) as f64, h / (1 + rng.below(8)) as f64, h / (1 + rng.below(8)) as f64);
    let dims = (DVec3::splat(11.0) / s).to_array().map(|d| (d.ceil() as u64).min(72));
    GridSpec::new(o, s, dims).unwrap()
}

/// `|got − want| ≤ 1e-5 voxel + half an f32 step of want`.
fn close(got: f32, want: f64, h: f64) -> bool {
    (got as f64 - want).abs() <= 1e-5 * h + want * f32::EPSILON as f64
}

#[test]
fn band_and_dense_match_the_reference() {
    let mut rng = Xorshift(0x5eed_d157);
    for round in 0..8 {
        let mesh = soup(&mut rng, 12 + round * 5);
        let g = grid(&mut rng);
        let want = reference::distances(mesh.as_ref(), &g).unwrap();
        let pieces = Pieces::of(mesh.as_ref()).unwrap();
        let dense = nearest::dense(&pieces, &g, &Stop::new()).unwrap();
        let [_, ny, nz] = g.dims().map(|d| d as usize);
        let at = |i: u32, j: u32, k: u32| (i as usize * ny + j as usize) * nz + k as usize;
        for (n, (&d, &w)) in dense.iter().zip(&want).enumerate() {
            assert!(close(d, w, g.voxel_size().0.max_element()), "round {round}: voxel {n}: dense {d}, reference {w}");
        }
        for width in [1.0, 2.5, 3.0] {
            let b = band::band(&pieces, &g, width, &Stop::new()).unwrap();
            let r = width * g.voxel_size().0.max_element();
            let mut seen = vec![false; want.len()];
            b.for_each(|i, j, k, d| {
                let n = at(i, j, k);
                seen[n] = true;
                assert_eq!(d.to_bits(), dense[n].to_bits(), "band and dense differ at {:?}", [i, j, k]);
            });
            for (n, &w) in want.iter().enumerate() {
                // Within rounding of the radius either answer is right.
                if (w - r).abs() > 1e-9 * r {
                    assert_eq!(seen[n], w < r, "round {round}, width {width}: voxel {n} at {w} (radius {r})");
                }
            }
        }
    }
}

#[test]
fn a_band_covering_the_grid_is_the_dense_field_with_the_same_values() {
    let mut rng = Xorshift(0x0c0f_fee5);
    for round in 0..6 {
        let mesh = soup(&mut rng, 8 + round * 3);
        let g = grid(&mut rng);
        let pieces = Pieces::of(mesh.as_ref()).unwrap();
        let h = g.voxel_size().0.max_element();
        // Wide enough to cover the grid: the dense route is taken, and
        // gives what the bricks give.
        let wide = 80.0 * g.dims().iter().copied().max().unwrap() as f64;
        assert!(band::covers_grid(&pieces, &g, wide * h), "round {round}");
        let fast = band::band(&pieces, &g, wide, &Stop::new()).unwrap();
        assert_eq!(fast, band::by_bricks(&pieces, &g, wide * h, &Stop::new()).unwrap(), "round {round}");
        assert_eq!(fast.count(), g.voxel_count());
        // A narrow band does not cover it.
        assert!(!band::covers_grid(&pieces, &g, 0.5 * h));
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let mut rng = Xorshift(0xabcd_0123);
    let mesh = soup(&mut rng, 60);
    let g = grid(&mut rng);
    let pieces = Pieces::of(mesh.as_ref()).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| (band::band(&pieces, &g, 3.0, &Stop::new()).unwrap(), nearest::dense(&pieces, &g, &Stop::new()).unwrap()))
    };
    let (b1, d1) = run(1);
    for t in [2, 3, 7] {
        let (b, d) = run(t);
        assert_eq!(b, b1);
        assert!(d.iter().zip(&d1).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}

#[test]
fn a_stop_returns_nothing() {
    let mut rng = Xorshift(7);
    let mesh = soup(&mut rng, 10);
    let pieces = Pieces::of(mesh.as_ref()).unwrap();
    let stop = Stop::new();
    stop.request();
    let g = grid(&mut rng);
    assert!(band::band(&pieces, &g, 3.0, &stop).is_none());
    assert!(nearest::dense(&pieces, &g, &stop).is_none());
}

#[test]
fn bad_meshes_are_refused_and_bad_indices_skipped() {
    let mut m = Mesh { positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y], triangles: vec![[0, 1, 2], [0, 1, 9]], segments: vec![] };
    assert_eq!(Pieces::of(m.as_ref()).unwrap().skipped, 1);
    m.positions[1].x = f64::NAN;
    assert_eq!(Pieces::of(m.as_ref()).unwrap_err(), DistanceError::NonFinite(1));
    assert_eq!(Pieces::of(Mesh::default().as_ref()).unwrap_err(), DistanceError::Empty);
}

#[test]
fn a_flat_triangle_is_its_edges() {
    // Collinear corners: the distance is to the segment they span.
    let m = Mesh { positions: vec![DVec3::ZERO, DVec3::X * 4.0, DVec3::X * 2.0], triangles: vec![[0, 1, 2]], segments: vec![] };
    let p = Pieces::of(m.as_ref()).unwrap();
    assert!(p.items[0].flat);
    assert_eq!(p.items[0].distance_squared(DVec3::new(3.0, 1.0, 0.0)), 1.0);
    assert_eq!(p.items[0].distance_squared(DVec3::new(5.0, 0.0, 0.0)), 1.0);
}

/// The four-wide walk finds the binary tree's nearest piece, bit for bit,
/// from any start: points near and far, on corners, and at coordinates
/// where the f32 slack matters (a soup moved far from the origin).
#[test]
fn the_wide_walk_equals_the_binary_one() {
    let mut rng = Xorshift(0x9e37_79b9_7f4a_7c15);
    for (round, shift) in [0.0, 3.0e5, -7.5e8].into_iter().enumerate() {
        let mut m = soup(&mut rng, 300 + 200 * round);
        m.positions.iter_mut().for_each(|p| *p += DVec3::splat(shift));
        let pieces = Pieces::of(m.as_ref()).unwrap();
        let tree = nearest::Hierarchy::new(&pieces);
        let mut checked = 0;
        for i in 0..3000 {
            let r = |rng: &mut Xorshift| rng.signed(1_000_000) as f64 * 1e-5;
            let q = match i % 4 {
                0 => m.positions[rng.below(m.positions.len() as u64) as usize],
                1 => DVec3::new(r(&mut rng), r(&mut rng), r(&mut rng)) * 0.1 + DVec3::splat(5.0 + shift),
                2 => DVec3::new(r(&mut rng), r(&mut rng), r(&mut rng)) * 3.0 + DVec3::splat(shift),
                _ => DVec3::new(r(&mut rng), r(&mut rng), r(&mut rng)) * 1e3 + DVec3::splat(shift),
            };
            let start = (f64::INFINITY, u32::MAX);
            let got = tree.nearest(q, start);
            assert_eq!(got, tree.nearest_binary(q, start), "round {round}, point {q}");
            // Every piece measured: the nearest, the lowest numbered of ties.
            let all = pieces.items.iter().enumerate().map(|(n, p)| (p.distance_squared(q), n as u32));
            let want = all.min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))).unwrap();
            assert_eq!(got, want, "round {round}, point {q}");
            checked += 1;
        }
        assert_eq!(checked, 3000);
    }
}
