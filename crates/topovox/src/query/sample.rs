//! Training samples: points on, near and around a mesh with their signed
//! distance and occupancy, as implicit-field training uses them.
//!
//! - **Surface**: area-weighted uniform points on the triangles (a
//!   triangle by its area, then `(1 − √u, √u(1 − v), √u·v)` weights: G.
//!   Turk, "Generating Random Points in Triangles", Graphics Gems, 1990),
//!   with the triangle's unit normal.
//! - **Near**: surface points displaced by an isotropic Gaussian of each
//!   standard deviation in `sigma` in turn (J. J. Park et al., "DeepSDF",
//!   CVPR 2019, §5; J. Chibane et al., "Implicit Functions in Feature
//!   Space" (IF-Net), CVPR 2020, §3.3 boundary sampling).
//! - **Uniform**: points uniform in a box (L. Mescheder et al., "Occupancy
//!   Networks", CVPR 2019, §4).
//!
//! Every point gets the [`Query`]'s signed distance and inside test, so
//! `sdf < 0` exactly where `occupancy`. The normal distribution is drawn
//! by the Box–Muller transform (two lines, so no crate for it).
//!
//! **Reproducible.** Points are drawn in blocks of [`BLOCK`], block `b` of
//! kind `k` from a ChaCha8 stream seeded by `(seed, k, b)`: the same
//! samples for a seed on any machine and thread count.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::{Ask, Query};

/// Points drawn from one random stream.
pub const BLOCK: usize = 4096;

/// What to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleSpec {
    /// Points on the surface.
    pub surface: usize,
    /// Points near the surface.
    pub near: usize,
    /// The near points' standard deviations (world units), used in turn.
    pub sigma: Vec<f64>,
    /// Points uniform in `bounds`.
    pub uniform: usize,
    /// The uniform points' box.
    pub bounds: (DVec3, DVec3),
    /// The random seed.
    pub seed: u64,
}

/// Which draw a sample came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// On the surface.
    Surface = 0,
    /// Near the surface.
    Near = 1,
    /// Uniform in the box.
    Uniform = 2,
}

/// Samples: surface points first, then near, then uniform.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Samples {
    /// The points.
    pub points: Vec<DVec3>,
    /// Their signed distances (negative inside).
    pub sdf: Vec<f64>,
    /// Inside or not.
    pub occupancy: Vec<bool>,
    /// The unit normal of the triangle a surface point lies on (NaN for
    /// the other kinds).
    pub normals: Vec<DVec3>,
    /// Which draw each point came from.
    pub kind: Vec<Kind>,
    /// The mesh's triangle a surface point lies on, and its barycentric
    /// weights there (`u32::MAX` and NaN for the other kinds): where its
    /// colour is read.
    pub faces: Vec<(u32, [f64; 3])>,
}

/// Triangles with area, for drawing surface points.
struct Areas {
    tris: Vec<(u32, [DVec3; 3])>,
    /// Running sum of the areas.
    cumulative: Vec<f64>,
}

impl Areas {
    fn new(tris: Vec<(u32, [DVec3; 3])>) -> Areas {
        let mut total = 0.0;
        let cumulative = tris
            .iter()
            .map(|(_, t)| {
                total += (t[1] - t[0]).cross(t[2] - t[0]).length() * 0.5;
                total
            })
            .collect();
        Areas { tris, cumulative }
    }

    fn total(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// A uniform point of the surface, its triangle's unit normal, and
    /// the triangle's number and the point's weights on it.
    fn draw(&self, rng: &mut ChaCha8Rng) -> (DVec3, DVec3, (u32, [f64; 3])) {
        let r = rng.random::<f64>() * self.total();
        let n = self.cumulative.partition_point(|&c| c <= r).min(self.tris.len() - 1);
        let (face, t) = &self.tris[n];
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        let s = u.sqrt();
        let w = [1.0 - s, s * (1.0 - v), s * v];
        let p = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
        (p, (t[1] - t[0]).cross(t[2] - t[0]).normalize(), (*face, w))
    }
}

/// A drawn point, its normal (NaN off the surface), and its triangle and
/// weights (`u32::MAX` and NaN off the surface).
type Drawn = (DVec3, DVec3, (u32, [f64; 3]));

/// A standard normal number (Box–Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u: f64 = 1.0 - rng.random::<f64>();
    let v: f64 = rng.random();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// Why samples could not be drawn.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// Surface or near points asked of a mesh without area.
    #[error("the mesh has no triangle with area to draw surface points from")]
    NoArea,
    /// A standard deviation that is not a positive number, or none.
    #[error("sigma must be positive numbers (got {0})")]
    Sigma(String),
    /// A box that is empty or not finite.
    #[error("bounds must be a finite box with low < high on every axis")]
    Bounds,
    /// Samples that could lie past ±[`crate::COORDINATE_LIMIT`], where their
    /// distances (and in f32, their coordinates) would not be finite.
    #[error("{0} would place samples past ±2^100 (1.27e30), the range topovox computes in; nothing was drawn")]
    Range(String),
}

/// How many standard deviations from its surface point a near sample can
/// lie: [`normal`] draws from uniform numbers no smaller than 2⁻⁵³
/// (`√(−2 ln 2⁻⁵³)` ≈ 8.6 per axis, 14.9 in all three), with a margin.
const MOST_DEVIATIONS: f64 = 16.5;

/// Refuses a spec whose samples could leave the range: a `sigma` so wide
/// (beside the mesh's triangles, as [`sample`] draws from them), or
/// `bounds` so far, that a point (or its distance) would overflow.
fn check_range(areas: &Areas, spec: &SampleSpec) -> Result<(), SampleError> {
    let reach = areas.tris.iter().flat_map(|(_, t)| t.iter().map(|p| p.abs().max_element())).fold(0.0, f64::max);
    if let Some(&s) = spec.sigma.iter().filter(|_| spec.near > 0).find(|&&s| reach + MOST_DEVIATIONS * s > crate::COORDINATE_LIMIT) {
        return Err(SampleError::Range(format!("sigma {s:e} (beside a mesh reaching {reach:e})")));
    }
    let (lo, hi) = spec.bounds;
    if spec.uniform > 0 && !(crate::in_range(lo) && crate::in_range(hi)) {
        return Err(SampleError::Range(format!("the bounds {:e}..{:e}", lo.min_element(), hi.max_element())));
    }
    Ok(())
}

/// Draws `spec`'s samples of the mesh behind `query`.
pub fn sample(query: &Query, spec: &SampleSpec) -> Result<Samples, SampleError> {
    let areas = Areas::new(query.faces());
    if (spec.surface > 0 || spec.near > 0) && !(areas.total() > 0.0 && areas.total().is_finite()) {
        return Err(SampleError::NoArea);
    }
    if spec.near > 0 && (spec.sigma.is_empty() || spec.sigma.iter().any(|s| !(*s > 0.0 && s.is_finite()))) {
        return Err(SampleError::Sigma(format!("{:?}", spec.sigma)));
    }
    let (lo, hi) = spec.bounds;
    if spec.uniform > 0 && !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
        return Err(SampleError::Bounds);
    }
    check_range(&areas, spec)?;
    let mut out = Samples::default();
    let nan = DVec3::NAN;
    let draws: [(Kind, usize); 3] = [(Kind::Surface, spec.surface), (Kind::Near, spec.near), (Kind::Uniform, spec.uniform)];
    for (kind, count) in draws {
        let none = (u32::MAX, [f64::NAN; 3]);
        let blocks: Vec<Vec<Drawn>> = (0..count.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
                rng.set_stream((kind as u64) << 48 | b as u64);
                let n = BLOCK.min(count - b * BLOCK);
                (0..n)
                    .map(|i| match kind {
                        Kind::Surface => areas.draw(&mut rng),
                        Kind::Near => {
                            let sigma = spec.sigma[(b * BLOCK + i) % spec.sigma.len()];
                            let p = areas.draw(&mut rng).0;
                            (p + DVec3::new(normal(&mut rng), normal(&mut rng), normal(&mut rng)) * sigma, nan, none)
                        }
                        Kind::Uniform => {
                            let t = DVec3::new(rng.random(), rng.random(), rng.random());
                            (lo + (hi - lo) * t, nan, none)
                        }
                    })
                    .collect()
            })
            .collect();
        for (p, n, f) in blocks.into_iter().flatten() {
            out.points.push(p);
            out.normals.push(n);
            out.kind.push(kind);
            out.faces.push(f);
        }
    }
    let mut inside = vec![0.0; out.points.len()];
    query.batch(&out.points, Ask::Contains, &mut inside);
    let mut dist = vec![0.0; out.points.len()];
    query.batch(&out.points, Ask::Distance, &mut dist);
    out.occupancy = inside.iter().map(|&v| v == 1.0).collect();
    out.sdf = dist.iter().zip(&out.occupancy).map(|(&d, &i)| super::signed(d, i)).collect();
    Ok(out)
}

/// How the mesh is moved and scaled before sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Normalize {
    /// As given.
    #[default]
    None,
    /// Box centre to the origin, longest side 1 (the box in `[−½, ½]³`;
    /// Occupancy Networks, IF-Net).
    UnitCube,
    /// Box centre to the origin, farthest vertex at distance 1 (DeepSDF).
    UnitSphere,
}

/// `(offset, scale)` such that `(p − offset) · scale` normalizes the
/// points `p` of `tris` as `how` says (`(0, 1)` for none or no extent).
pub fn normalization(tris: &[[DVec3; 3]], how: Normalize) -> (DVec3, f64) {
    let pts = || tris.iter().flatten();
    let (lo, hi) = pts().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let centre = (lo + hi) * 0.5;
    let size = match how {
        Normalize::None => return (DVec3::ZERO, 1.0),
        Normalize::UnitCube => (hi - lo).max_element(),
        Normalize::UnitSphere => pts().map(|p| p.distance(centre)).fold(0.0, f64::max),
    };
    if size > 0.0 && size.is_finite() {
        (centre, 1.0 / size)
    } else {
        (DVec3::ZERO, 1.0)
    }
}

/// The default box of the uniform points: the box of `tris` grown by 5 %
/// of its longest side on every side.
pub fn default_bounds(tris: &[[DVec3; 3]]) -> (DVec3, DVec3) {
    let (lo, hi) = tris.iter().flatten().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let pad = DVec3::splat((hi - lo).max_element() * 0.05);
    (lo - pad, hi + pad)
}
