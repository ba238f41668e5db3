//! Point queries against brute force: distances against the reference
//! formula, crossings against every triangle, winding numbers against the
//! direct sum of solid angles, and batches against single points.

use glam::DVec3;

use super::caps::solid_angle;
use super::ray::crosses;
use super::{Ask, Query, Sign};
use crate::distance::{reference, DistanceError, Pieces};
use crate::test_rng::Xorshift;
use crate::Mesh;

/// A closed octahedron-like blob: `n` random radii over a sphere's
/// vertices (a UV sphere of 6 rings), centred at `c`.
fn blob(rng: &mut Xorshift, c: DVec3) -> Mesh {
    let n = 6u32;
    let r = |rng: &mut Xorshift| 1.0 + rng.below(1000) as f64 * 1e-3;
    let mut positions = vec![c + DVec3::Z * r(rng), c - DVec3::Z * r(rng)];
    for ring in 1..n {
        let th = std::f64::consts::PI * ring as f64 / n as f64;
        for s in 0..2 * n {
            let ph = std::f64::consts::PI * s as f64 / n as f64;
            positions.push(c + r(rng) * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    let at = |ring: u32, s: u32| 2 + (ring - 1) * 2 * n + (s % (2 * n));
    let mut triangles = Vec::new();
    for s in 0..2 * n {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        triangles.push([1, at(n - 1, s + 1), at(n - 1, s)]);
        for ring in 1..n - 1 {
            triangles.push([at(ring, s), at(ring + 1, s), at(ring + 1, s + 1)]);
            triangles.push([at(ring, s), at(ring + 1, s + 1), at(ring, s + 1)]);
        }
    }
    Mesh { positions, triangles, segments: Vec::new() }
}

fn point(rng: &mut Xorshift, lo: f64, hi: f64) -> DVec3 {
    let f = |rng: &mut Xorshift| lo + (hi - lo) * rng.below(1 << 20) as f64 / (1 << 20) as f64;
    DVec3::new(f(rng), f(rng), f(rng))
}

/// A soup of `n` random triangles in `[0, 4]³`, some degenerate, and two segments.
fn soup(rng: &mut Xorshift, n: usize) -> Mesh {
    let mut m = Mesh::default();
    for t in 0..n {
        let a = point(rng, 0.0, 4.0);
        let b = if t % 7 == 3 { a } else { a + point(rng, -1.0, 1.0) };
        let c = if t % 5 == 1 { a + (b - a) * 0.5 } else { a + point(rng, -1.0, 1.0) };
        let base = m.positions.len() as u32;
        m.positions.extend([a, b, c]);
        m.triangles.push([base, base + 1, base + 2]);
    }
    for _ in 0..2 {
        let base = m.positions.len() as u32;
        let a = point(rng, 0.0, 4.0);
        m.positions.extend([a, a + DVec3::new(1.5, -0.5, 0.25)]);
        m.segments.push([base, base + 1]);
    }
    m
}

#[test]
fn distances_and_closest_points_match_brute_force() {
    let mut rng = Xorshift(11);
    for round in 0..6 {
        let m = soup(&mut rng, 40 + round * 30);
        let q = Query::new(m.as_ref(), Sign::Auto).unwrap();
        let pieces = Pieces::of(m.as_ref()).unwrap();
        for _ in 0..400 {
            let p = point(&mut rng, -1.0, 5.0);
            let want = reference::distance_at(&pieces, p);
            let got = q.distance(p);
            assert!((got - want).abs() <= 1e-9 * want.max(1e-300), "{p}: {got} vs {want}");
            let c = q.closest(p);
            assert_eq!(c.distance, got);
            assert!((c.point.distance(p) - got).abs() <= 1e-9 * (1.0 + got), "{p}: closest point at {} not {got}", c.point.distance(p));
            // The point is on its element, with weights summing to 1.
            let e = c.element as usize;
            let corners: Vec<DVec3> = if e < m.triangles.len() {
                m.triangles[e].iter().map(|&i| m.positions[i as usize]).collect()
            } else {
                let s = m.segments[e - m.triangles.len()];
                vec![m.positions[s[0] as usize], m.positions[s[1] as usize], DVec3::ZERO]
            };
            let at = corners[0] * c.weights[0] + corners[1] * c.weights[1] + corners[2] * c.weights[2];
            assert!(at.distance(c.point) <= 1e-9 * (1.0 + at.length()), "{p}: weights {:?}", c.weights);
            assert!((c.weights.iter().sum::<f64>() - 1.0).abs() < 1e-9 && c.weights.iter().all(|&w| w >= -1e-12));
        }
    }
}

#[test]
fn ties_go_to_the_lowest_element_in_any_order() {
    // Two copies of one triangle: every point's nearest is the first.
    let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let m = Mesh { positions: vec![t[0], t[1], t[2], t[0], t[1], t[2]], triangles: vec![[3, 4, 5], [0, 1, 2]], segments: vec![] };
    let q = Query::new(m.as_ref(), Sign::Auto).unwrap();
    let pts: Vec<DVec3> = (0..5000).map(|n| DVec3::new((n % 71) as f64 * 0.03 - 0.5, (n % 37) as f64 * 0.05 - 0.5, 0.2)).collect();
    let mut out = vec![super::Closest { point: DVec3::ZERO, distance: 0.0, element: 7, weights: [0.0; 3] }; pts.len()];
    q.closest_batch(&pts, &mut out);
    assert!(out.iter().all(|c| c.element == 0));
}

#[test]
fn parity_and_winding_count_every_crossing() {
    let mut rng = Xorshift(5);
    for round in 0..4 {
        let m = soup(&mut rng, 30 + 20 * round);
        let tris: Vec<[DVec3; 3]> = m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
        let parity = Query::new(m.as_ref(), Sign::Parity).unwrap();
        let winding = Query::new(m.as_ref(), Sign::Winding).unwrap();
        let turned = crate::query::orient::orient(m.as_ref()).triangles;
        let oriented: Vec<[DVec3; 3]> = turned.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
        assert!(!parity.facts().watertight);
        for _ in 0..300 {
            // Points on a coarse lattice, so some rays pass through edges and vertices.
            let p = (point(&mut rng, -0.5, 4.5) * 4.0).round() / 4.0;
            let count = tris.iter().filter(|t| crosses(t, p).is_some()).count();
            assert_eq!(parity.contains(p), count % 2 == 1, "{p}");
            // The winding number is the oriented mesh's.
            let direct: f64 = oriented.iter().map(|t| solid_angle(t, p)).sum::<f64>() / (4.0 * std::f64::consts::PI);
            let w = winding.winding_number(p);
            assert!((w - direct).abs() < 1e-9, "{p}: {w} vs the direct sum {direct}");
            assert_eq!(winding.contains(p), w.abs() >= 0.5);
        }
    }
}

#[test]
fn a_closed_mesh_has_integer_winding_numbers_and_parity() {
    let mut rng = Xorshift(9);
    let a = blob(&mut rng, DVec3::ZERO);
    let b = blob(&mut rng, DVec3::new(0.4, 0.1, -0.2));
    // Two overlapping closed shells: winding 2 where both hold a point.
    let mut m = a.clone();
    let base = m.positions.len() as u32;
    m.positions.extend(&b.positions);
    m.triangles.extend(b.triangles.iter().map(|t| t.map(|i| i + base)));
    let auto = Query::new(m.as_ref(), Sign::Auto).unwrap();
    assert!(auto.facts().watertight && auto.facts().sign == Sign::Winding);
    // Auto is the union (nonzero); parity by name cuts the overlap out.
    let parity = Query::new(m.as_ref(), Sign::Parity).unwrap();
    let (qa, qb) = (Query::new(a.as_ref(), Sign::Auto).unwrap(), Query::new(b.as_ref(), Sign::Auto).unwrap());
    let tris: Vec<[DVec3; 3]> = m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
    for _ in 0..2000 {
        let p = point(&mut rng, -1.5, 1.5);
        let w = auto.winding_number(p);
        let want = qa.contains(p) as i32 + qb.contains(p) as i32;
        assert_eq!(w, want as f64, "{p}");
        assert_eq!(auto.contains(p), want >= 1);
        assert_eq!(parity.contains(p), want == 1);
        let direct: f64 = tris.iter().map(|t| solid_angle(t, p)).sum::<f64>() / (4.0 * std::f64::consts::PI);
        assert!((direct - w).abs() < 1e-9);
        let d = auto.signed_distance(p);
        assert_eq!(d < 0.0, want >= 1);
        assert_eq!(d.abs(), auto.distance(p));
    }
}

#[test]
fn a_point_on_a_face_takes_the_tie_rules_side() {
    // The unit cube; points on its faces, edges and corners.
    let mut m = Mesh::default();
    let c = |i: u32| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64);
    m.positions = (0..8).map(c).collect();
    for q in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
        m.triangles.push([q[0], q[1], q[2]]);
        m.triangles.push([q[0], q[2], q[3]]);
    }
    let q = Query::new(m.as_ref(), Sign::Auto).unwrap();
    // δ = −(ε, ε², ε³) moves a point towards −x, −y, −z: off the low
    // faces, into the cube from the high ones.
    for (p, inside) in [
        (DVec3::new(0.0, 0.5, 0.5), false),
        (DVec3::new(1.0, 0.5, 0.5), true),
        (DVec3::new(0.5, 0.0, 0.5), false),
        (DVec3::new(0.5, 1.0, 0.5), true),
        (DVec3::new(0.5, 0.5, 0.0), false),
        (DVec3::new(0.5, 0.5, 1.0), true),
        (DVec3::new(1.0, 0.0, 0.5), false),
        (DVec3::new(1.0, 1.0, 0.0), false),
        (DVec3::ZERO, false),
        (DVec3::ONE, true),
        (DVec3::new(0.5, 0.5, 0.5), true),
    ] {
        assert_eq!(q.contains(p), inside, "{p}");
        assert_eq!(q.winding_number(p), inside as i32 as f64, "{p}");
        if p != DVec3::splat(0.5) {
            assert_eq!(q.distance(p), 0.0);
            assert_eq!(q.signed_distance(p) < 0.0, inside);
        }
    }
}

#[test]
fn batches_equal_single_points_and_bad_points_are_nan() {
    let mut rng = Xorshift(3);
    let m = blob(&mut rng, DVec3::ZERO);
    let q = Query::new(m.as_ref(), Sign::Auto).unwrap();
    let mut pts: Vec<DVec3> = (0..10_000).map(|_| point(&mut rng, -2.0, 2.0)).collect();
    pts[17] = DVec3::new(f64::NAN, 0.0, 0.0);
    pts[4000] = DVec3::new(0.0, f64::INFINITY, 0.0);
    for ask in [Ask::Distance, Ask::SignedDistance, Ask::Contains, Ask::WindingNumber] {
        let mut out = vec![0.0; pts.len()];
        q.batch(&pts, ask, &mut out);
        for (n, &p) in pts.iter().enumerate() {
            let want = match ask {
                Ask::Distance => q.distance(p),
                Ask::SignedDistance => q.signed_distance(p),
                Ask::Contains => q.contains(p) as u8 as f64,
                Ask::WindingNumber => q.winding_number(p),
            };
            assert!(out[n].to_bits() == want.to_bits(), "{ask:?} at {p}: {} vs {want}", out[n]);
        }
    }
    assert!(q.distance(pts[17]).is_nan() && !q.contains(pts[4000]) && q.closest(pts[17]).element == u32::MAX);
    assert_eq!(Query::new(Mesh::default().as_ref(), Sign::Auto).err(), Some(DistanceError::Empty));
}

#[test]
fn samples_are_reproducible_and_signed_by_the_query() {
    use super::sample::{sample, Kind, SampleSpec};
    let mut rng = Xorshift(21);
    let m = blob(&mut rng, DVec3::ZERO);
    let q = Query::new(m.as_ref(), Sign::Auto).unwrap();
    let spec = SampleSpec {
        surface: 5000,
        near: 9000,
        sigma: vec![0.05, 0.01],
        uniform: 4100,
        bounds: (DVec3::splat(-2.0), DVec3::splat(2.0)),
        seed: 7,
    };
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| sample(&q, &spec).unwrap());
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| sample(&q, &spec).unwrap());
    assert_eq!(one.points.len(), 18_100);
    assert!(one.points.iter().zip(&two.points).all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits)));
    let other = sample(&q, &SampleSpec { seed: 8, ..spec.clone() }).unwrap();
    assert_ne!(one.points[..10], other.points[..10]);
    for (n, &p) in one.points.iter().enumerate() {
        assert_eq!(one.sdf[n] < 0.0, one.occupancy[n]);
        assert_eq!(one.sdf[n], super::signed(q.distance(p), one.occupancy[n]));
        assert_eq!(one.occupancy[n], q.contains(p));
        match one.kind[n] {
            Kind::Surface => {
                assert!(one.sdf[n].abs() < 1e-12);
                assert!((one.normals[n].length() - 1.0).abs() < 1e-12);
            }
            Kind::Near => assert!(one.normals[n].is_nan() && one.sdf[n].abs() < 0.5),
            Kind::Uniform => assert!(p.cmpge(DVec3::splat(-2.0)).all() && p.cmplt(DVec3::splat(2.0)).all()),
        }
    }
    // The two sigmas alternate: their spreads show.
    let spread = |k: usize| {
        let d: Vec<f64> = (5000..14_000).filter(|n| (n - 5000) % 2 == k).map(|n| one.sdf[n].abs()).collect();
        d.iter().sum::<f64>() / d.len() as f64
    };
    assert!(spread(0) > 3.0 * spread(1), "{} {}", spread(0), spread(1));
    let bad = SampleSpec { sigma: vec![0.0], ..spec.clone() };
    assert!(sample(&q, &bad).is_err());
}

#[test]
fn a_flat_fan_sums_to_a_full_turn_at_its_inner_edges_and_corners() {
    // A fan of six triangles around an inner vertex, in planes tilted every
    // way (x̂ out of the plane, and in it); at the inner vertex, on the
    // inner edges and inside, the angles sum to ±2π, and they sum to 0
    // beyond the fan.
    // Dyadic corners and integer frames: the fans are exactly flat.
    let ring: Vec<DVec3> =
        [(1.0, 0.0), (0.5, 1.0), (-0.5, 1.0), (-1.0, 0.0), (-0.5, -1.0), (0.5, -1.0)].iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    let frames = [
        (DVec3::X, DVec3::Y),
        (DVec3::Y, DVec3::Z),
        (DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 2.0)),
        (DVec3::new(2.0, -1.0, 1.0), DVec3::new(1.0, 1.0, -3.0)),
        (DVec3::new(0.0, 3.0, 1.0), DVec3::X),
    ];
    for (fu, fv) in frames {
        let at = |p: DVec3| DVec3::new(0.25, -0.5, 0.75) + fu * p.x + fv * p.y;
        let fan: Vec<[DVec3; 3]> = (0..6).map(|i| [at(DVec3::ZERO), at(ring[i]), at(ring[(i + 1) % 6])]).collect();
        let total = |q: DVec3| fan.iter().map(|t| solid_angle(t, q)).sum::<f64>();
        let tau = std::f64::consts::TAU;
        for p in [DVec3::ZERO, ring[0] * 0.5, ring[1] * 0.25, DVec3::new(0.1, 0.05, 0.0)] {
            let w = total(at(p));
            assert!((w.abs() - tau).abs() < 1e-9, "{fu} {fv} at {p}: {w}");
        }
        assert!(total(at(DVec3::new(3.0, 0.1, 0.0))).abs() < 1e-9);
    }
}
