//! Property tests: random edge-case triangles, random grids, and
//! metamorphic relations, for the `cover` definition and its fast path.

use glam::DVec3;
use proptest::prelude::*;
use topovox::voxelize::driver::Driver;
use topovox::voxelize::Mode;
use topovox::voxelize::{cover, Options};
use topovox::{DenseBits, GridSpec, Mesh};
use topovox_testkit::strategies::{small_triangle, triangle};
use topovox_testkit::{agree, agree_mode, soup};

fn unit_grid(n: u64) -> GridSpec {
    GridSpec::new(DVec3::ZERO, 1.0, [n, n, n]).unwrap()
}

fn fast(m: &Mesh, g: &GridSpec) -> DenseBits {
    cover::cover(m.as_ref(), g, &Options::default()).0.to_dense()
}

fn voxels(b: &DenseBits) -> Vec<[u32; 3]> {
    let mut v = Vec::new();
    b.for_each_set(|i, j, k| v.push([i, j, k]));
    v.sort();
    v
}

/// Draws the k-th z-layer, row j = top, '#' = set.
fn slice(b: &DenseBits, k: u32) -> String {
    let d = b.dims();
    (0..d[1]).rev().map(|j| (0..d[0]).map(|i| if b.get(i, j, k) { '#' } else { '.' }).collect::<String>() + "\n").collect()
}

#[test]
fn hand_drawn_right_triangle() {
    // In the plane z = 0.5; the hypotenuse x + y = 4 passes through voxel
    // corners, which count as touches.
    let m = soup(&[[DVec3::new(0.5, 0.5, 0.5), DVec3::new(3.5, 0.5, 0.5), DVec3::new(0.5, 3.5, 0.5)]]);
    let g = GridSpec::new(DVec3::ZERO, 1.0, [4, 4, 1]).unwrap();
    let b = agree(&m, &g).unwrap();
    assert_eq!(slice(&b, 0), "##..\n###.\n####\n####\n");
}

#[test]
fn triangle_in_a_grid_plane_sets_both_layers() {
    let m = soup(&[[DVec3::new(0.5, 0.5, 2.0), DVec3::new(2.5, 0.5, 2.0), DVec3::new(0.5, 2.5, 2.0)]]);
    let b = agree(&m, &unit_grid(4)).unwrap();
    assert_eq!(slice(&b, 1), slice(&b, 2));
    assert_eq!(slice(&b, 1), "....\n##..\n###.\n###.\n");
    assert_eq!(slice(&b, 0), "....\n....\n....\n....\n");
}

#[test]
fn degenerate_triangles_draw_nothing_and_are_counted() {
    let m =
        soup(&[[DVec3::ONE, DVec3::new(2.0, 2.0, 2.0), DVec3::new(3.0, 3.0, 3.0)], [DVec3::ONE, DVec3::ONE, DVec3::new(1.0, 2.0, 1.0)]]);
    let (b, rep) = cover::cover(m.as_ref(), &unit_grid(4), &Options::default());
    assert_eq!(b.count(), 0);
    assert_eq!(rep.prepare.degenerate, 2);
}

#[test]
fn nan_and_bad_indices_are_skipped_and_counted() {
    let mut m = soup(&[[DVec3::ONE, DVec3::new(2.0, 1.0, 1.0), DVec3::new(1.0, 2.0, 1.0)]]);
    m.positions.push(DVec3::new(f64::NAN, 0.0, 0.0));
    m.triangles.push([0, 1, 3]);
    m.triangles.push([0, 1, 99]);
    // A corner far outside: the triangle is clipped to the grid's margin.
    m.positions.push(DVec3::new(1.0e12, 1.5, 1.5));
    m.triangles.push([0, 2, 4]);
    for driver in [Driver::Auto, Driver::Slabs, Driver::Triangles] {
        let (b, rep) = cover::cover(m.as_ref(), &unit_grid(4), &Options { driver, ..Options::default() });
        assert_eq!(rep.prepare.non_finite, 1, "{driver:?}");
        assert_eq!(rep.prepare.invalid_index, 1, "{driver:?}");
        assert_eq!(rep.prepare.input, 4, "{driver:?}");
        let (want, wrep) = cover::reference::cover(m.as_ref(), &unit_grid(4));
        assert_eq!(rep, wrep, "{driver:?}");
        assert_eq!(b.to_dense(), want, "{driver:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn fast_equals_reference_on_edge_case_triangles(tris in prop::collection::vec(triangle(), 1..4)) {
        let m = soup(&tris);
        if let Err(e) = agree(&m, &unit_grid(8)) {
            prop_assert!(false, "{e}\ntriangles: {tris:?}");
        }
    }

    /// Triangles of a few voxels, through every surface mode: the short
    /// paths (one voxel, one run, one 2D projection, the tiny-box test)
    /// against the definitions, on both drivers.
    #[test]
    fn small_triangles_in_every_surface_mode(tris in prop::collection::vec(small_triangle(), 1..5)) {
        let m = soup(&tris);
        for mode in [Mode::Cover, Mode::Sep26, Mode::Sep6, Mode::Ss6] {
            if let Err(e) = agree_mode(mode, &m, &unit_grid(8)) {
                prop_assert!(false, "{e}\ntriangles: {tris:?}");
            }
        }
    }

    #[test]
    fn fast_equals_reference_on_random_grids(
        tris in prop::collection::vec(triangle(), 1..3),
        origin in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        size in 0.3f64..2.5,
        dims in (1u64..9, 1u64..9, 1u64..9),
    ) {
        let m = soup(&tris);
        let g = GridSpec::new(DVec3::new(origin.0, origin.1, origin.2), size, [dims.0, dims.1, dims.2]).unwrap();
        if let Err(e) = agree(&m, &g) {
            prop_assert!(false, "{e}\ntriangles: {tris:?}\ngrid: {g:?}");
        }
    }

    #[test]
    fn fast_equals_reference_on_huge_triangles_crossing_the_grid(
        tris in prop::collection::vec(prop::array::uniform3((-600.0f64..600.0, -600.0f64..600.0, -4.0f64..16.0)), 1..3),
        center in (0.0f64..12.0, 0.0f64..12.0, 0.0f64..12.0),
    ) {
        // Triangles hundreds of voxels wide (the i128 plane path) that cut
        // through a 12³ grid: clipping and wide arithmetic at once.
        let c = DVec3::new(center.0, center.1, center.2);
        let tris: Vec<[DVec3; 3]> = tris.iter().map(|t| t.map(|(x, y, z)| c + DVec3::new(x, y, z - 6.0))).collect();
        let m = soup(&tris);
        if let Err(e) = agree(&m, &unit_grid(12)) {
            prop_assert!(false, "{e}\ntriangles: {tris:?}");
        }
    }

    #[test]
    fn translating_by_whole_voxels_shifts_the_result(tris in prop::collection::vec(triangle(), 1..3), t in (0i32..3, 0i32..3, 0i32..3)) {
        let m = soup(&tris);
        let shift = DVec3::new(t.0 as f64, t.1 as f64, t.2 as f64);
        let mut moved = m.clone();
        moved.transform(|p| p + shift);
        // Grid moved with the mesh: identical voxels.
        let g = unit_grid(8);
        let g2 = GridSpec::new(shift, 1.0, [8, 8, 8]).unwrap();
        prop_assert_eq!(fast(&m, &g), fast(&moved, &g2));
    }

    #[test]
    fn permuting_axes_permutes_voxels(tris in prop::collection::vec(triangle(), 1..3)) {
        let m = soup(&tris);
        let mut p = m.clone();
        p.transform(|v| DVec3::new(v.y, v.z, v.x));
        let a = voxels(&fast(&m, &unit_grid(8)));
        let mut b: Vec<[u32; 3]> = voxels(&fast(&p, &unit_grid(8))).into_iter().map(|[i, j, k]| [k, i, j]).collect();
        b.sort();
        prop_assert_eq!(a, b);
    }

    #[test]
    fn winding_and_order_do_not_matter(tris in prop::collection::vec(triangle(), 1..4)) {
        let m = soup(&tris);
        let flipped: Vec<[DVec3; 3]> = tris.iter().rev().map(|t| [t[0], t[2], t[1]]).collect();
        prop_assert_eq!(fast(&m, &unit_grid(8)), fast(&soup(&flipped), &unit_grid(8)));
    }

    #[test]
    fn splitting_a_triangle_in_four_changes_nothing(v in prop::array::uniform3((-2048i64..20480, -2048i64..20480, -2048i64..20480))) {
        // Vertices on the even lattice points (multiples of 2/4096 voxel) so
        // the midpoints are lattice points and the four halves tile the
        // triangle exactly.
        let p = v.map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64) * (2.0 / 4096.0));
        let mid = |a: DVec3, b: DVec3| (a + b) * 0.5;
        let (m01, m12, m20) = (mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0]));
        let whole = soup(&[p]);
        let parts = soup(&[[p[0], m01, m20], [m01, p[1], m12], [m20, m12, p[2]], [m01, m12, m20]]);
        let (a, ra) = cover::cover(whole.as_ref(), &unit_grid(8), &Options::default());
        let b = fast(&parts, &unit_grid(8));
        prop_assume!(ra.prepare.degenerate == 0);
        prop_assert_eq!(a.to_dense(), b);
    }
}

/// A large triangle across a 48³ grid: general, or nearly parallel to a
/// grid plane (the scanline path then emits whole runs along its rows).
fn large_triangle() -> impl Strategy<Value = [DVec3; 3]> {
    let p = || (-4.0f64..52.0, -4.0f64..52.0, -4.0f64..52.0).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    prop_oneof![
        (p(), p(), p()).prop_map(|(a, b, c)| [a, b, c]),
        (p(), p(), p(), 0usize..3, -0.3f64..0.3, -0.3f64..0.3).prop_map(|(mut a, mut b, mut c, axis, s, t)| {
            // w = base + s·(first other coordinate) + t·(second): shallow along w.
            let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = a[axis];
            for q in [&mut a, &mut b, &mut c] {
                q[axis] = base + s * q[o1] + t * q[o2];
            }
            [a, b, c]
        }),
        (p(), p(), 0usize..3, (0i32..48)).prop_map(|(a, b, axis, k)| {
            // Exactly in a grid plane.
            let (mut a, mut b) = (a, b);
            a[axis] = k as f64;
            b[axis] = k as f64;
            let mut c = (a + b) * 0.5;
            c[(axis + 1) % 3] += 17.0;
            [a, b, c]
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Large triangles take the scanline path's row walk with runs (along
    /// the row for shallow planes, along w otherwise); every mode with a
    /// scanline path must still equal its definition.
    #[test]
    fn large_triangles_in_every_scanline_mode(tris in prop::collection::vec(large_triangle(), 1..3)) {
        let m = soup(&tris);
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [48, 48, 48]).unwrap();
        for mode in [topovox::voxelize::Mode::Cover, topovox::voxelize::Mode::Sep26, topovox::voxelize::Mode::Sep6] {
            if let Err(e) = topovox_testkit::agree_mode(mode, &m, &grid) {
                prop_assert!(false, "{e}\ntriangles: {tris:?}");
            }
        }
    }
}
