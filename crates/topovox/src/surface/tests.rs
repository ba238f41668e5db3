use glam::DVec3;

use super::*;
use crate::mesh_check::check_mesh;
use crate::test_rng::Xorshift;
use crate::MeshRef;

fn random_bits(rng: &mut Xorshift, dims: [u32; 3], percent: u64) -> DenseBits {
    let mut b = DenseBits::new(dims);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                if rng.below(100) < percent {
                    b.set(i, j, k);
                }
            }
        }
    }
    b
}

/// The winding number of a closed mesh at `q` (sum of solid angles,
/// Van Oosterom and Strackee 1983); the tests' points are far from it.
fn winding(m: &TriMesh, q: DVec3) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize] - q);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * num.atan2(den)
        })
        .sum::<f64>()
        / (4.0 * std::f64::consts::PI)
}

/// Certifies `m` and checks it separates exactly: winding 1 at every
/// inside voxel centre, 0 at every other.
fn certified(m: &TriMesh, inside: &DenseBits, grid: &GridSpec) {
    let r = check_mesh(&m.positions, &m.triangles, &Stop::new()).unwrap();
    assert!(r.watertight(), "{r:?}");
    let d = inside.dims();
    for k in 0..d[2] {
        for j in 0..d[1] {
            for i in 0..d[0] {
                let w = winding(m, grid.voxel_center([i, j, k]));
                let want = inside.get(i, j, k) as i32 as f64;
                assert!((w - want).abs() < 1e-6, "voxel {i},{j},{k}: winding {w}, inside {want}");
            }
        }
    }
}

fn grid(dims: [u32; 3]) -> GridSpec {
    GridSpec::new(DVec3::new(0.25, -1.0, 3.0), 0.5, dims.map(u64::from)).unwrap()
}

#[test]
fn the_fast_extraction_equals_the_reference() {
    let mut rng = Xorshift(11);
    for round in 0..12 {
        let dims = [3 + round % 5, 70 - round, 4 + round % 3];
        let bits = random_bits(&mut rng, dims, 20 + 5 * round as u64);
        let fast = tets::extract(&bits, &Stop::new()).unwrap();
        let slow = tets::reference::extract(&bits);
        let tri = |e: &tets::Extracted| {
            let mut t: Vec<Vec<([i64; 3], [i64; 3])>> = e
                .triangles
                .iter()
                .map(|t| {
                    let v = t.map(|v| e.crossings[v as usize]);
                    // Rotated to start at the smallest vertex: orientation kept.
                    let m = (0..3).min_by_key(|&n| v[n]).unwrap();
                    (0..3).map(|n| v[(m + n) % 3]).collect()
                })
                .collect();
            t.sort();
            t
        };
        assert_eq!(tri(&fast), tri(&slow), "round {round}");
    }
}

/// Slabs of any thickness concatenate to the whole surface, and each
/// slab's triangles use only its own and the previous slab's vertices
/// (what a writer streaming the parts relies on).
#[test]
fn slabs_of_any_thickness_are_the_whole_surface() {
    let mut rng = Xorshift(23);
    for round in 0..10 {
        let dims = [5 + round % 4, 9, 6 + round];
        let bits = random_bits(&mut rng, dims, 25 + 6 * round as u64);
        let whole = tets::extract(&bits, &Stop::new()).unwrap();
        for thickness in [1, 2, 3, 7, dims[2], u32::MAX] {
            let mut all = tets::Extracted::default();
            let mut previous_first = 0u32;
            tets::extract_slabs(&bits, thickness, &Stop::new(), |s| {
                assert_eq!(s.first_vertex as usize, all.crossings.len(), "thickness {thickness}");
                let end = s.first_vertex + s.crossings.len() as u32;
                assert!(s.triangles.iter().flatten().all(|&v| (previous_first..end).contains(&v)), "thickness {thickness}");
                previous_first = s.first_vertex;
                all.crossings.extend(s.crossings);
                all.triangles.extend(s.triangles);
                Ok::<(), ()>(())
            })
            .unwrap()
            .unwrap();
            assert_eq!(all, whole, "round {round}, thickness {thickness}");
        }
        let g = grid(dims);
        let mut parts = TriMesh::default();
        blocky_parts(&bits, &g, 2 + round % 3, &Stop::new(), &mut |p: Part| {
            assert_eq!(p.first_vertex as usize, parts.positions.len());
            parts.positions.extend(p.positions);
            parts.triangles.extend(p.triangles);
            Ok::<(), ()>(())
        })
        .unwrap()
        .unwrap();
        assert_eq!(parts, blocky(&bits, &g, &Stop::new()).unwrap());
    }
}

/// A stop requested before the surface is made gives `None`; an error
/// from the taker ends it at the first slab.
#[test]
fn slabs_end_on_a_stop_or_an_error() {
    let bits = random_bits(&mut Xorshift(3), [6, 6, 40], 40);
    let stop = Stop::new();
    stop.request();
    assert_eq!(tets::extract(&bits, &stop), None);
    let mut calls = 0;
    let r = tets::extract_slabs(&bits, 8, &Stop::new(), |_| {
        calls += 1;
        Err("full")
    });
    assert_eq!((r, calls), (Err("full"), 1));
}

#[test]
fn random_voxels_give_certified_separating_surfaces() {
    let mut rng = Xorshift(5);
    for round in 0..8 {
        let dims = [4 + round % 3, 5, 3 + round % 4];
        let bits = random_bits(&mut rng, dims, 30 + 8 * round as u64);
        let g = grid(dims);
        certified(&blocky(&bits, &g, &Stop::new()).unwrap(), &bits, &g);
        // Distances to a random soup, unrelated to the labels: any vertex
        // placement strictly inside the edges keeps every guarantee.
        let positions: Vec<DVec3> =
            (0..9).map(|_| g.origin() + DVec3::new(rng.below(40) as f64, rng.below(40) as f64, rng.below(40) as f64) * 0.1).collect();
        let triangles = [[0, 1, 2], [3, 4, 5], [6, 7, 8], [0, 4, 8]];
        let pieces = Pieces::of(MeshRef { positions: &positions, triangles: &triangles, segments: &[] }).unwrap();
        for offset in [None, Some(0.3)] {
            certified(
                &smooth(&bits, &g, Smooth { pieces: &pieces, tree: &Hierarchy::new(&pieces), offset }, &Stop::new()).unwrap(),
                &bits,
                &g,
            );
        }
    }
}

#[test]
fn diagonal_voxels_stay_manifold() {
    // Two voxels meeting along an edge, two at a corner, and their complements.
    for pattern in [vec![[0, 0, 0], [1, 1, 0]], vec![[0, 0, 0], [1, 1, 1]], vec![[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]] {
        let mut bits = DenseBits::new([2, 2, 2]);
        for p in &pattern {
            bits.set(p[0], p[1], p[2]);
        }
        let g = grid([2, 2, 2]);
        certified(&blocky(&bits, &g, &Stop::new()).unwrap(), &bits, &g);
    }
}

#[test]
fn smooth_surfaces_of_a_ball_are_certified_and_near_it() {
    // An octahedron-ish ball mesh: distances come from its triangles.
    let (positions, triangles) = sphere(2.0, DVec3::new(2.5, 2.5, 2.5), 12);
    let mesh = MeshRef { positions: &positions, triangles: &triangles, segments: &[] };
    let (g, inside) = ball(0.5, 10);
    let pieces = Pieces::of(mesh).unwrap();
    let m = smooth(&inside, &g, Smooth { pieces: &pieces, tree: &Hierarchy::new(&pieces), offset: None }, &Stop::new()).unwrap();
    certified(&m, &inside, &g);
    let far = m.positions.iter().map(|p| ((*p - DVec3::splat(2.5)).length() - 2.0).abs()).fold(0.0, f64::max);
    assert!(far < 0.2, "a vertex {far} from the sphere");
}

/// A grid of `n`³ voxels of size `h` from the origin, and the centres
/// within 2 of (2.5, 2.5, 2.5).
fn ball(h: f64, n: u32) -> (GridSpec, DenseBits) {
    let g = GridSpec::new(DVec3::ZERO, h, [n as u64; 3]).unwrap();
    let mut inside = DenseBits::new([n; 3]);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                if (g.voxel_center([i, j, k]) - DVec3::splat(2.5)).length() < 2.0 {
                    inside.set(i, j, k);
                }
            }
        }
    }
    (g, inside)
}

/// A UV sphere: `n` rings of `2n` quads, split into triangles.
fn sphere(r: f64, c: DVec3, n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut p = vec![c + DVec3::Z * r, c - DVec3::Z * r];
    for a in 1..n {
        for b in 0..2 * n {
            let (th, ph) = (std::f64::consts::PI * a as f64 / n as f64, std::f64::consts::PI * b as f64 / n as f64);
            p.push(c + r * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    let at = |a: u32, b: u32| 2 + (a - 1) * 2 * n + b % (2 * n);
    let mut t = Vec::new();
    for b in 0..2 * n {
        t.push([0, at(1, b), at(1, b + 1)]);
        t.push([1, at(n - 1, b + 1), at(n - 1, b)]);
        for a in 1..n - 1 {
            t.push([at(a, b), at(a + 1, b), at(a + 1, b + 1)]);
            t.push([at(a, b), at(a + 1, b + 1), at(a, b + 1)]);
        }
    }
    (p, t)
}

#[test]
fn refine_and_dilate_are_what_they_say() {
    let mut rng = Xorshift(3);
    let bits = random_bits(&mut rng, [67, 3, 2], 10);
    let (r, d) = (refine(&bits), dilate(&bits));
    for k in 0..4 {
        for j in 0..6 {
            for i in 0..134 {
                assert_eq!(r.get(i, j, k), bits.get(i / 2, j / 2, k / 2));
            }
        }
    }
    for k in 0..2i64 {
        for j in 0..3i64 {
            for i in 0..67i64 {
                let near = (-1..=1).any(|a| (-1..=1).any(|b| (-1..=1).any(|c| bits.get_signed(i + a, j + b, k + c))));
                assert_eq!(d.get(i as u32, j as u32, k as u32), near, "{i} {j} {k}");
            }
        }
    }
    assert_eq!(d.words().len(), bits.words().len());
    assert!(d.words().chunks(2).all(|row| row[1] >> 3 == 0), "padding stays clear");
}

#[test]
fn small_parts_go_only_when_asked() {
    let mut bits = DenseBits::new([8, 8, 8]);
    bits.fill_box([0, 0, 0], [2, 2, 2]);
    bits.set(5, 5, 5);
    bits.set(6, 6, 6); // 26-connected to (5, 5, 5): one part of two voxels
    bits.set(7, 0, 7);
    assert_eq!(drop_small_parts(bits.clone(), 0), (bits.clone(), 3, 0));
    let (kept, n, dropped) = drop_small_parts(bits.clone(), 2);
    assert_eq!((n, dropped, kept.count()), (2, 1, 29));
    assert!(!kept.get(7, 0, 7) && kept.get(6, 6, 6));
}

#[test]
fn simplified_surfaces_keep_every_guarantee() {
    // Random voxels (many small parts, tunnels and cavities) and a ball:
    // blocky and smooth surfaces lose faces and stay certified and
    // separating, at every bound.
    let mut rng = Xorshift(17);
    let (positions, triangles) = sphere(2.0, DVec3::new(2.5, 2.5, 2.5), 12);
    let pieces = Pieces::of(MeshRef { positions: &positions, triangles: &triangles, segments: &[] }).unwrap();
    let mut fewer = 0;
    for round in 0..6u32 {
        let dims = [6 + round % 3, 7, 5 + round % 4];
        let bits = random_bits(&mut rng, dims, 25 + 10 * round as u64);
        let g = grid(dims);
        for m in [
            blocky(&bits, &g, &Stop::new()).unwrap(),
            smooth(&bits, &g, Smooth { pieces: &pieces, tree: &Hierarchy::new(&pieces), offset: None }, &Stop::new()).unwrap(),
        ] {
            for bound in [0.25, 1.0, 2.0] {
                let s = simplify::simplify(&m, &g, bound * 0.5, &Stop::new()).unwrap();
                certified(&s, &bits, &g);
                assert!(s.triangles.len() <= m.triangles.len());
                fewer += (s.triangles.len() < m.triangles.len()) as u32;
            }
        }
    }
    assert!(fewer >= 30, "only {fewer} of 36 surfaces lost faces");
    // The ball: a large flat-ish surface loses most of its faces.
    let (g, inside) = ball(0.25, 20);
    let m = blocky(&inside, &g, &Stop::new()).unwrap();
    let s = simplify::simplify(&m, &g, 0.25, &Stop::new()).unwrap();
    certified(&s, &inside, &g);
    assert!(s.triangles.len() * 4 < m.triangles.len(), "{} of {}", s.triangles.len(), m.triangles.len());
}
