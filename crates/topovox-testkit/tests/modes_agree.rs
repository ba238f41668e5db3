//! Every topological mode's fast path equals its reference voxel for voxel
//! on real meshes, rotated meshes, clipped grids, huge triangles and lattice
//! edge cases (vertices on corners, faces on grid planes).

use glam::DVec3;
use topovox::voxelize::Mode;
use topovox::GridSpec;
use topovox_testkit::{agree_mode, box_mesh, random_rotation, rng, rotated, shared_mesh, soup, SHARED_MESHES};

const SURFACE: [Mode; 8] =
    [Mode::Sep26, Mode::Sep6, Mode::Ss6, Mode::Pos, Mode::Tunnel18, Mode::Tunnel26, Mode::Bubble { seed: 7 }, Mode::Diagonal];

#[test]
fn every_shared_mesh_every_surface_mode() {
    let mut r = rng(0x70b0);
    for name in SHARED_MESHES {
        let mesh = shared_mesh(name);
        let rot = rotated(&mesh, random_rotation(&mut r));
        for (m, res) in [(&mesh, 41), (&rot, 33)] {
            let grid = GridSpec::from_resolution(&m.as_ref().bounds(), res).unwrap();
            for mode in SURFACE {
                let bits = agree_mode(mode, m, &grid).unwrap_or_else(|e| panic!("{name} at {res}: {e}"));
                assert!(bits.count() > 0, "{name} {mode:?}: empty");
            }
        }
    }
}

#[test]
fn grid_aligned_boxes_hit_every_tie() {
    // Faces on grid planes, on voxel-centre planes and half-way between;
    // vertices on corners and face centres.
    for (lo, hi) in [
        (DVec3::new(1.0, 1.0, 1.0), DVec3::new(5.0, 4.0, 3.0)),
        (DVec3::new(1.5, 1.5, 1.5), DVec3::new(4.5, 3.5, 5.5)),
        (DVec3::new(1.25, 0.5, 2.0), DVec3::new(4.75, 3.0, 2.5)),
    ] {
        let m = box_mesh(lo, hi);
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [7, 6, 7]).unwrap();
        for mode in SURFACE.into_iter().chain([Mode::Line26, Mode::Line6]) {
            agree_mode(mode, &m, &grid).unwrap_or_else(|e| panic!("{lo} {hi}: {e}"));
        }
        let rot = rotated(&m, random_rotation(&mut rng(lo.x.to_bits())));
        let grid = GridSpec::from_resolution(&rot.as_ref().bounds(), 9).unwrap();
        for mode in SURFACE {
            agree_mode(mode, &rot, &grid).unwrap();
        }
    }
}

#[test]
fn huge_triangles_take_the_wide_arithmetic_path() {
    // Faces of a box 90 voxels wide exceed the i64 bound of the target tests.
    let m = box_mesh(DVec3::new(0.3, 0.2, 0.1), DVec3::new(90.3, 70.7, 80.9));
    let rot = rotated(&m, random_rotation(&mut rng(11)));
    let grid = GridSpec::from_resolution(&rot.as_ref().bounds(), 96).unwrap();
    for mode in SURFACE {
        agree_mode(mode, &rot, &grid).unwrap();
    }
}

#[test]
fn single_large_triangles_on_half_voxels() {
    // One triangle per mesh (no neighbour hides a wrong voxel), a few to a
    // dozen voxels wide so the column paths and the target lines' spans run, vertices on grid planes
    // and voxel-centre planes so ties are common.
    use rand::Rng;
    let mut r = rng(0x5516);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [16, 15, 17]).unwrap();
    for n in 0..30 {
        let p = |r: &mut rand::rngs::SmallRng| {
            DVec3::new(r.random_range(2..28) as f64, r.random_range(2..26) as f64, r.random_range(2..30) as f64) * 0.5
        };
        let m = soup(&[[p(&mut r), p(&mut r), p(&mut r)]]);
        for mode in [Mode::Sep26, Mode::Sep6, Mode::Ss6, Mode::Diagonal] {
            agree_mode(mode, &m, &grid).unwrap_or_else(|e| panic!("triangle {n}: {e}"));
        }
    }
}

#[test]
fn explicit_grid_clipping_the_mesh() {
    let mesh = shared_mesh("cow.obj");
    let b = mesh.as_ref().bounds();
    let e = b.extent();
    let grid = GridSpec::new(b.min + e * 0.3, e.max_element() / 40.0, [16, 13, 19]).unwrap();
    for mode in SURFACE {
        assert!(agree_mode(mode, &mesh, &grid).unwrap().count() > 0);
    }
}

#[test]
fn thin_tubes_as_triangles_in_line_modes() {
    // A long sliver triangle: effective dimension 1.
    let m = soup(&[[DVec3::new(0.3, 0.4, 0.2), DVec3::new(9.1, 6.3, 7.7), DVec3::new(9.1, 6.35, 7.72)]]);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [10, 8, 9]).unwrap();
    for mode in [Mode::Line26, Mode::Line6] {
        assert!(agree_mode(mode, &m, &grid).unwrap().count() >= 9);
    }
}

mod polylines {
    use super::*;
    use proptest::prelude::*;
    use topovox::Mesh;
    use topovox_testkit::strategies::point;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

        /// `line6`'s exact integer walk and `line26`'s filtered walk against
        /// the definitions, on polylines whose points sit on voxel corners,
        /// edges, faces and a few ulps off them.
        #[test]
        fn random_polylines_in_line_modes(pts in prop::collection::vec(point(), 2..6)) {
            let mesh = Mesh {
                positions: pts.clone(),
                triangles: Vec::new(),
                segments: (0..pts.len() as u32 - 1).map(|i| [i, i + 1]).collect(),
            };
            let grid = GridSpec::new(DVec3::ZERO, 1.0, [8, 8, 8]).unwrap();
            for mode in [Mode::Line6, Mode::Line26] {
                if let Err(e) = agree_mode(mode, &mesh, &grid) {
                    prop_assert!(false, "{e}\npoints: {pts:?}");
                }
            }
        }
    }
}
