//! Fuzzes the point queries: a soup of triangles (degenerate ones
//! included) from raw bytes, points from the rest (NaN and infinities
//! too). Distances must equal the brute-force reference, parity the
//! crossings of every triangle counted one by one, the winding number the
//! direct sum of solid angles over the oriented triangles; nothing may
//! panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox::distance::{reference, Pieces};
use topovox::glam::DVec3;
use topovox::query::caps::solid_angle;
use topovox::query::ray::RayIndex;
use topovox::query::{Ask, Query, Sign};
use topovox::Mesh;

fuzz_target!(|data: &[u8]| {
    let Some((&split, rest)) = data.split_first() else { return };
    let at = (split as usize * 18).min(rest.len());
    let (mesh_bytes, point_bytes) = rest.split_at(at - at % 18);
    let coord = |c: &[u8]| i16::from_le_bytes([c[0], c[1]]) as f64 / 2048.0;
    let positions: Vec<DVec3> = mesh_bytes.chunks_exact(6).map(|c| DVec3::new(coord(&c[0..2]), coord(&c[2..4]), coord(&c[4..6]))).collect();
    let n = positions.len() as u32;
    let mesh = Mesh { positions, triangles: (0..n / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(), segments: Vec::new() };
    let points: Vec<DVec3> = point_bytes
        .chunks_exact(6)
        .map(|c| match c[0] {
            0xff => DVec3::new(f64::NAN, 0.0, 0.0),
            0xfe => DVec3::new(0.0, f64::INFINITY, 0.0),
            _ => DVec3::new(coord(&c[0..2]), coord(&c[2..4]), coord(&c[4..6])),
        })
        .collect();
    let Ok(parity) = Query::new(mesh.as_ref(), Sign::Parity) else { return };
    let winding = Query::new(mesh.as_ref(), Sign::Winding).expect("the same mesh");
    let pieces = Pieces::of(mesh.as_ref()).expect("the same mesh");
    let tris: Vec<[DVec3; 3]> = mesh.triangles.iter().map(|t| t.map(|i| mesh.positions[i as usize])).collect();
    let one = RayIndex::new(tris.iter().copied());
    // The winding number is the mesh's as `orient` turns it (issue 66).
    let turned = topovox::query::orient::orient(mesh.as_ref()).triangles;
    let oriented: Vec<[DVec3; 3]> = turned.iter().map(|t| t.map(|i| mesh.positions[i as usize])).collect();
    let mut batch = vec![0.0; points.len()];
    parity.batch(&points, Ask::Distance, &mut batch);
    for (k, &p) in points.iter().enumerate() {
        let d = parity.distance(p);
        assert_eq!(d.to_bits(), batch[k].to_bits(), "batch and single differ at {p}");
        if !p.is_finite() {
            assert!(d.is_nan() && !parity.contains(p));
            continue;
        }
        // Within 1e-9 relative, and rounding of the coordinates' size
        // (a point on a triangle measures about 1e-15, not 0).
        let want = reference::distance_at(&pieces, p);
        let size = 1.0 + p.abs().max_element() + mesh.positions.iter().fold(0.0f64, |m, v| m.max(v.abs().max_element()));
        assert!((d - want).abs() <= 1e-9 * want + 1e-12 * size, "{p}: {d} vs {want}");
        let count = tris.iter().filter(|t| topovox::query::ray::crosses(t, p).is_some()).count();
        assert_eq!(parity.contains(p), count % 2 == 1, "{p}");
        assert_eq!(one.crossings(p).count as usize, count, "{p}");
        // On the surface the sum of solid angles is undefined (the tie
        // rule decides there); off it the two must agree.
        if d > 1e-6 {
            let direct: f64 = oriented.iter().map(|t| solid_angle(t, p)).sum::<f64>() / (4.0 * std::f64::consts::PI);
            let w = winding.winding_number(p);
            assert!((w - direct).abs() < 1e-6, "{p}: {w} vs {direct}");
        }
    }
});
