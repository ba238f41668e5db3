//! 2D rasterization (Laine 2013 §4): every mode's fast path equals its
//! reference pixel for pixel, curves are 4- (8-) connected and 8- (4-)
//! separating, and filling is exact (a fan covers each pixel centre once).

use glam::DVec2;
use proptest::prelude::*;
use rand::Rng;
use topovox::choice::Choice;
use topovox::raster::certify::{components, inside, separation_witness, Adjacency};
use topovox::raster::{self, Grid2, Outline, Pixels, RasterMode};
use topovox_testkit::rng;

fn grid(n: u64) -> Grid2 {
    Grid2::new(DVec2::ZERO, 1.0, [n, n]).unwrap()
}

fn agree(outlines: &[Outline], g: &Grid2) -> Result<Vec<(RasterMode, Pixels)>, String> {
    RasterMode::ALL
        .iter()
        .map(|&m| {
            let (f, fr) = raster::fast(m, outlines, g);
            let (r, rr) = raster::reference(m, outlines, g);
            if let Some(p) = r.first_difference(&f) {
                return Err(format!("{m:?}: fast and reference differ at pixel {p:?}"));
            }
            if fr != rr {
                return Err(format!("{m:?}: reports differ: {fr:?} vs {rr:?}"));
            }
            Ok((m, f))
        })
        .collect()
}

/// The connectivity a mode guarantees for a curve, and the one its
/// complement is separated in.
fn guarantee(m: RasterMode) -> (Adjacency, Adjacency) {
    match m {
        RasterMode::Curve4 => (Adjacency::Four, Adjacency::Eight),
        _ => (Adjacency::Eight, Adjacency::Four),
    }
}

/// A regular star (alternating radii) or polygon, rotated.
fn star(c: DVec2, r0: f64, r1: f64, n: usize, angle: f64) -> Outline {
    let points = (0..2 * n)
        .map(|k| {
            let a = angle + k as f64 * std::f64::consts::PI / n as f64;
            c + DVec2::new(a.cos(), a.sin()) * if k % 2 == 0 { r0 } else { r1 }
        })
        .collect();
    Outline::new(points, true)
}

fn certify_closed(o: &Outline, g: &Grid2, what: &str) {
    let pix = agree(std::slice::from_ref(o), g).unwrap_or_else(|e| panic!("{what}: {e}"));
    let ins = inside(std::slice::from_ref(o), g);
    for (m, px) in pix {
        if m == RasterMode::Fill {
            continue;
        }
        let (conn, sep) = guarantee(m);
        assert_eq!(components(&px, conn), 1, "{what} {m:?}: not {conn:?}-connected");
        assert_eq!(separation_witness(&px, &ins, sep), None, "{what} {m:?}: not {sep:?}-separating");
    }
}

#[test]
fn rotated_stars_and_polygons_are_connected_and_separating() {
    let mut r = rng(0x2d);
    for n in [3, 4, 5, 7, 12] {
        for _ in 0..6 {
            let angle = r.random_range(0.0..std::f64::consts::TAU);
            let c = DVec2::new(r.random_range(30.0..34.0), r.random_range(30.0..34.0));
            certify_closed(&star(c, 25.0, r.random_range(5.0..25.0), n, angle), &grid(64), &format!("star {n}"));
        }
    }
}

#[test]
fn the_certifier_sees_the_weaker_connectivity() {
    // curve8 and diamond are only 4-separating and 8-connected: on slanted
    // shapes an 8-leak and a 4-disconnection show up, so the checks above
    // are not vacuous.
    let (mut leaks, mut splits) = (0, 0);
    let mut r = rng(0x99);
    for _ in 0..10 {
        let o = star(DVec2::splat(32.0), 25.0, 12.0, 5, r.random_range(0.0..6.3));
        let g = grid(64);
        let ins = inside(std::slice::from_ref(&o), &g);
        let (px, _) = raster::fast(RasterMode::Curve8, std::slice::from_ref(&o), &g);
        leaks += separation_witness(&px, &ins, Adjacency::Eight).is_some() as u32;
        splits += (components(&px, Adjacency::Four) > 1) as u32;
    }
    assert!(leaks > 0 && splits > 0, "{leaks} {splits}");
}

#[test]
fn shapes_on_pixel_corners_and_midpoints_hit_every_tie() {
    // Edges along grid lines and through pixel centres, vertices on corners
    // and midpoints: the tie rule decides every one.
    for (lo, hi) in [(4.0, 20.0), (4.5, 20.5), (4.0, 20.5), (3.25, 19.75)] {
        let sq = Outline::new(vec![DVec2::splat(lo), DVec2::new(hi, lo), DVec2::splat(hi), DVec2::new(lo, hi)], true);
        certify_closed(&sq, &grid(24), &format!("square {lo}-{hi}"));
        let diamond = Outline::new(vec![DVec2::new(12.0, lo), DVec2::new(hi, 12.0), DVec2::new(12.0, hi), DVec2::new(lo, 12.0)], true);
        certify_closed(&diamond, &grid(24), &format!("diamond {lo}-{hi}"));
    }
}

#[test]
fn a_fan_covers_each_pixel_centre_exactly_once() {
    let mut r = rng(0xfa);
    for _ in 0..20 {
        // A convex polygon and its fan from an interior point, as separate
        // consistently oriented triangles.
        let c = DVec2::new(r.random_range(14.0..18.0), r.random_range(14.0..18.0));
        let poly = star(c, 12.0, 12.0, r.random_range(3..9), r.random_range(0.0..6.3));
        let g = grid(32);
        let (whole, _) = raster::fast(RasterMode::Fill, std::slice::from_ref(&poly), &g);
        let mut sum = vec![0u32; 32 * 32];
        let hub = if r.random_bool(0.5) { c } else { c.round() };
        for k in 0..poly.points.len() {
            let t = Outline::new(vec![hub, poly.points[k], poly.points[(k + 1) % poly.points.len()]], true);
            let (px, _) = raster::fast(RasterMode::Fill, std::slice::from_ref(&t), &g);
            let (rf, _) = raster::reference(RasterMode::Fill, std::slice::from_ref(&t), &g);
            assert_eq!(px.first_difference(&rf), None);
            for j in 0..32 {
                for i in 0..32 {
                    sum[j * 32 + i] += px.get(i as i64, j as i64) as u32;
                }
            }
        }
        for j in 0..32 {
            for i in 0..32 {
                assert_eq!(sum[j * 32 + i], whole.get(i as i64, j as i64) as u32, "pixel {i} {j} covered {} times", sum[j * 32 + i]);
            }
        }
    }
}

#[test]
fn thin_quads_behave_like_curves() {
    // Strokes drawn as thin closed quads (effective dimension 1) under the
    // curve modes: connected like the curve they stand for.
    let mut r = rng(0x7c);
    for _ in 0..30 {
        let a = DVec2::new(r.random_range(2.0..30.0), r.random_range(2.0..30.0));
        let b = DVec2::new(r.random_range(2.0..30.0), r.random_range(2.0..30.0));
        let n = (b - a).perp().normalize_or_zero() * 0.01;
        let quad = Outline::new(vec![a, b, b + n, a + n], true);
        for (m, px) in agree(std::slice::from_ref(&quad), &grid(32)).unwrap() {
            if m != RasterMode::Fill {
                assert_eq!(components(&px, guarantee(m).0), 1, "{m:?} {a} {b}");
            }
        }
    }
}

fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![(0i32..=16).prop_map(|i| i as f64), (0i32..=32).prop_map(|i| i as f64 * 0.5), 0.0f64..16.0]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Random polylines (points on corners, midpoints and anywhere): fast =
    /// reference for every mode, and each curve is connected.
    #[test]
    fn random_polylines(pts in prop::collection::vec((coord(), coord()), 2..7), closed in any::<bool>()) {
        let o = Outline::new(pts.iter().map(|&(x, y)| DVec2::new(x + 1.0, y + 1.0)).collect(), closed);
        let g = grid(19);
        let pix = agree(std::slice::from_ref(&o), &g).map_err(TestCaseError::fail)?;
        for (m, px) in pix {
            if m != RasterMode::Fill && px.count() > 0 {
                prop_assert_eq!(components(&px, guarantee(m).0), 1, "{:?}", m);
            }
        }
    }
}

#[test]
fn fill_rules_and_unfilled_outlines_follow_svg_painting() {
    // A pentagram {5/2}: its centre winds twice, so nonzero fills it and
    // evenodd leaves a pentagon hole; the arms are filled by both.
    let c = DVec2::splat(16.0);
    let pts: Vec<DVec2> = (0..5)
        .map(|k| {
            let a = 0.3 + k as f64 * 4.0 * std::f64::consts::PI / 5.0;
            c + DVec2::new(a.cos(), a.sin()) * 14.0
        })
        .collect();
    let g = grid(32);
    let mut star = Outline::new(pts.clone(), true);
    let nonzero = agree(std::slice::from_ref(&star), &g).unwrap().pop().unwrap().1;
    star.fill = Some(raster::FillRule::EvenOdd);
    let evenodd = agree(std::slice::from_ref(&star), &g).unwrap().pop().unwrap().1;
    assert!(nonzero.get(16, 16) && !evenodd.get(16, 16));
    let arm = (c + (pts[0] - c) * 0.8).floor();
    assert!(nonzero.get(arm.x as i64, arm.y as i64) && evenodd.get(arm.x as i64, arm.y as i64));
    assert!(evenodd.count() < nonzero.count());
    // An unfilled open spiral: no pixel of `fill`, every pixel of a curve.
    let spiral: Vec<DVec2> =
        (0..60).map(|k| c + DVec2::new((k as f64 * 0.4).cos(), (k as f64 * 0.4).sin()) * (2.0 + k as f64 * 0.2)).collect();
    let stroke = Outline { fill: None, shape: 1, ..Outline::new(spiral, false) };
    let (f, rep) = raster::fast(RasterMode::Fill, std::slice::from_ref(&stroke), &g);
    assert_eq!((f.count(), rep.segments), (0, 0));
    assert_eq!(raster::drawn(RasterMode::Fill, std::slice::from_ref(&stroke)), 0);
    let (curve, _) = raster::fast(RasterMode::Curve8, std::slice::from_ref(&stroke), &g);
    assert!(curve.count() > 40);
}

fn painted() -> impl Strategy<Value = Outline> {
    let fill = prop_oneof![Just(None), Just(Some(raster::FillRule::NonZero)), Just(Some(raster::FillRule::EvenOdd))];
    (prop::collection::vec((coord(), coord()), 2..7), any::<bool>(), fill, 0u32..3).prop_map(|(pts, closed, fill, shape)| Outline {
        fill,
        shape,
        ..Outline::new(pts.iter().map(|&(x, y)| DVec2::new(x + 1.0, y + 1.0)).collect(), closed)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 150, ..ProptestConfig::default() })]

    /// Random painted outlines in up to three shapes: fast = reference for
    /// every mode; `fill` is the union of its shapes filled alone, and the
    /// curve modes draw every outline, filled or not.
    #[test]
    fn shapes_fill_alone_and_unite(outlines in prop::collection::vec(painted(), 1..5)) {
        let g = grid(19);
        let pix = agree(&outlines, &g).map_err(TestCaseError::fail)?;
        for (m, px) in pix {
            let mut union = Pixels::new(g.dims());
            for o in &outlines {
                let same: Vec<Outline> =
                    outlines.iter().filter(|p| p.shape == o.shape && p.fill == o.fill).cloned().collect();
                let alone: Vec<Outline> = if m == RasterMode::Fill { same } else { vec![Outline { fill: None, ..o.clone() }] };
                union.union_with(&raster::fast(m, &alone, &g).0);
            }
            prop_assert_eq!(px.first_difference(&union), None, "{:?}", m);
        }
    }
}
