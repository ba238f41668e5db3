//! Rasterization: voxelization in 2D (Laine 2013, §4), with the same
//! lattice, tie rule and reference-versus-fast discipline as the 3D modes.
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §4 (intersection
//! targets in 2D: the diagonal cross of Fig. 5c for 4-connected curves, the
//! crosshair and the diamond of Fig. 7c–d for 8-connected ones) and §3.2
//! (the tie rule: targets displaced by `δ = −(ε, ε²)`).
//!
//! - [`Grid2`]: pixel `(i, j)` is the closed square `[origin + (i, j)·s,
//!   origin + (i+1, j+1)·s]`, as voxels are in 3D.
//! - [`Outline`]: a polyline, closed or not, in plane coordinates, with how
//!   `fill` paints it (a [`FillRule`], or not at all) and the shape it
//!   belongs to (one SVG element's subpaths are filled together).
//! - [`curve`]: `curve4`, `curve8`, `diamond` — a pixel is set iff an
//!   outline's segment meets its target, filled or not; [`fill`]: `fill` — a
//!   pixel is set iff its displaced centre is inside some filled shape by
//!   that shape's fill rule. Each has a brute-force reference in a
//!   `reference` module.
//! - [`certify`]: 4- and 8-connectivity and separation of pixel sets.
//!
//! Coordinates are snapped to `1/4096` pixel ([`crate::geom::fixed::snap`]);
//! after that every decision is exact integer arithmetic, so fast paths and
//! references agree pixel for pixel.

pub mod certify;
pub mod curve;
pub mod fill;
pub mod predicates;

use glam::DVec2;

use crate::geom::fixed::{snap, DIRECT_LIMIT_VOXELS};

/// A lattice point in 2D (pixel units × 4096).
pub type P2 = [i64; 2];

/// Where the pixels are: origin, pixel size, dims.
///
/// # Guarantees
/// Built only through its constructors: origin finite, pixel size positive
/// and finite, `1 <= dims[a] <= 65 536`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid2 {
    origin: DVec2,
    pixel: f64,
    dims: [u32; 2],
}

/// Why a 2D grid could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Grid2Error {
    /// Non-positive, NaN or infinite pixel size.
    #[error("pixel size must be a positive finite number, got {0}")]
    BadPixelSize(f64),
    /// Non-finite origin.
    #[error("origin must be finite, got {0:?}")]
    BadOrigin([f64; 2]),
    /// Dims outside `1..=65536`.
    #[error("dims must each be between 1 and 65536, got {0:?}")]
    BadDims([u64; 2]),
    /// Resolution outside `1..=65536`.
    #[error("resolution must be between 1 and 65536, got {0}")]
    BadResolution(u64),
    /// No points, or they coincide.
    #[error("cannot fit a grid to outlines of zero extent")]
    ZeroExtent,
}

const MAX_DIM2: u64 = 65_536;

impl Grid2 {
    /// An explicit grid.
    pub fn new(origin: DVec2, pixel: f64, dims: [u64; 2]) -> Result<Grid2, Grid2Error> {
        if !(pixel.is_finite() && pixel > 0.0) {
            return Err(Grid2Error::BadPixelSize(pixel));
        }
        if !origin.is_finite() {
            return Err(Grid2Error::BadOrigin(origin.to_array()));
        }
        if dims.iter().any(|&d| d == 0 || d > MAX_DIM2) {
            return Err(Grid2Error::BadDims(dims));
        }
        Ok(Grid2 { origin, pixel, dims: dims.map(|d| d as u32) })
    }

    /// The longest side of `(lo, hi)` spans `n` pixels; origin `lo`.
    pub fn from_resolution(lo: DVec2, hi: DVec2, n: u64) -> Result<Grid2, Grid2Error> {
        if n == 0 || n > MAX_DIM2 {
            return Err(Grid2Error::BadResolution(n));
        }
        let ext = hi - lo;
        if !ext.is_finite() || ext.max_element() <= 0.0 {
            return Err(Grid2Error::ZeroExtent);
        }
        let s = ext.max_element() / n as f64;
        let dims = ext.to_array().map(|e| ((e / s).ceil() as u64).clamp(1, n));
        Grid2::new(lo, s, dims)
    }

    /// Pixels of size `s` fitted to `(lo, hi)`.
    pub fn from_pixel_size(lo: DVec2, hi: DVec2, s: f64) -> Result<Grid2, Grid2Error> {
        if !(s.is_finite() && s > 0.0) {
            return Err(Grid2Error::BadPixelSize(s));
        }
        let ext = hi - lo;
        if !ext.is_finite() {
            return Err(Grid2Error::ZeroExtent);
        }
        let dims = ext.to_array().map(|e| ((e / s).ceil() as u64).max(1));
        Grid2::new(lo, s, dims)
    }

    /// Pixels along x and y.
    pub fn dims(&self) -> [u32; 2] {
        self.dims
    }

    /// The low corner.
    pub fn origin(&self) -> DVec2 {
        self.origin
    }

    /// A pixel's side.
    pub fn pixel_size(&self) -> f64 {
        self.pixel
    }

    /// A plane point on the lattice of this grid, or `None` if it is not
    /// finite or too far from the grid to snap exactly.
    pub fn snap(&self, p: DVec2) -> Option<P2> {
        let u = (p - self.origin) / self.pixel;
        (u.is_finite() && u.abs().max_element() <= DIRECT_LIMIT_VOXELS).then(|| [snap(u.x), snap(u.y)])
    }
}

crate::choice! {
    /// SVG's fill rules (`fill-rule`): which winding numbers are inside.
    pub enum FillRule: "fill rule" default NonZero {
        /// Inside where the winding number is not zero (SVG's default).
        NonZero = "nonzero",
        /// Inside where the winding number is odd.
        EvenOdd = "evenodd",
    }
}

impl FillRule {
    /// Is a point of winding number `w` inside?
    #[inline]
    pub fn inside(self, w: i32) -> bool {
        match self {
            FillRule::NonZero => w != 0,
            FillRule::EvenOdd => w & 1 != 0,
        }
    }
}

/// A polyline in plane coordinates; `closed` joins the last point to the
/// first.
///
/// For `fill`, the outlines sharing a `shape` number and a fill rule form
/// one shape, filled together (an SVG `<path>`'s subpaths, each closed);
/// the shapes are filled one by one and their pixels united, as SVG paints
/// elements. An outline whose `fill` is `None` is not filled: only the
/// curve modes draw it. [`Outline::new`] gives nonzero fill in shape 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    /// The points.
    pub points: Vec<DVec2>,
    /// Whether the last point joins the first.
    pub closed: bool,
    /// How `fill` paints it; `None`: not filled.
    pub fill: Option<FillRule>,
    /// The shape it belongs to for `fill`.
    pub shape: u32,
}

impl Default for Outline {
    fn default() -> Outline {
        Outline::new(Vec::new(), false)
    }
}

impl Outline {
    /// A filled (nonzero) outline of shape 0.
    pub fn new(points: Vec<DVec2>, closed: bool) -> Outline {
        Outline { points, closed, fill: Some(FillRule::NonZero), shape: 0 }
    }

    /// Its segments, the closing one included.
    pub fn segments(&self) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
        let n = self.points.len();
        let m = if self.closed && n > 2 { n } else { n.saturating_sub(1) };
        (0..m).map(move |i| (self.points[i], self.points[(i + 1) % n]))
    }

    /// The same points, closed.
    pub fn closed(&self) -> Outline {
        Outline { closed: true, ..self.clone() }
    }
}

/// How many outlines a mode draws: every outline for the curve modes, the
/// filled ones for `fill`.
pub fn drawn(mode: RasterMode, outlines: &[Outline]) -> usize {
    match mode {
        RasterMode::Fill => outlines.iter().filter(|o| o.fill.is_some()).count(),
        _ => outlines.len(),
    }
}

/// What rasterizing skipped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RasterReport {
    /// Segments in the input.
    pub segments: u64,
    /// Skipped: a non-finite point, or too far from the grid to snap.
    pub skipped: u64,
    /// Skipped: zero length after snapping.
    pub degenerate: u64,
    /// Pixels set.
    pub pixels: u64,
}

/// Snapped segments of the outlines, skipping (and counting) the ones that
/// cannot be snapped or have zero length.
pub fn snap_segments(outlines: &[Outline], grid: &Grid2) -> (Vec<[P2; 2]>, RasterReport) {
    let mut r = RasterReport::default();
    let mut out = Vec::new();
    for o in outlines {
        for (a, b) in o.segments() {
            r.segments += 1;
            match (grid.snap(a), grid.snap(b)) {
                (Some(a), Some(b)) if a == b => r.degenerate += 1,
                (Some(a), Some(b)) => out.push([a, b]),
                _ => r.skipped += 1,
            }
        }
    }
    (out, r)
}

/// A set of pixels, one bit each, rows along `i`.
#[derive(Clone, PartialEq, Eq)]
pub struct Pixels {
    dims: [u32; 2],
    words_per_row: usize,
    words: Vec<u64>,
}

impl std::fmt::Debug for Pixels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Pixels {{ dims: {:?}, set: {} }}", self.dims, self.count())
    }
}

impl Pixels {
    /// All clear.
    pub fn new(dims: [u32; 2]) -> Pixels {
        let words_per_row = (dims[0] as usize).div_ceil(64);
        Pixels { dims, words_per_row, words: vec![0; words_per_row * dims[1] as usize] }
    }

    /// Pixels along x and y.
    pub fn dims(&self) -> [u32; 2] {
        self.dims
    }

    /// Is `(i, j)` set? `false` outside the grid.
    #[inline]
    pub fn get(&self, i: i64, j: i64) -> bool {
        if i < 0 || j < 0 || i >= self.dims[0] as i64 || j >= self.dims[1] as i64 {
            return false;
        }
        (self.words[j as usize * self.words_per_row + (i as usize >> 6)] >> (i & 63)) & 1 == 1
    }

    /// Sets `(i, j)` (inside the grid).
    #[inline]
    pub fn set(&mut self, i: u32, j: u32) {
        self.words[j as usize * self.words_per_row + (i as usize >> 6)] |= 1 << (i & 63);
    }

    /// Number of set pixels.
    pub fn count(&self) -> u64 {
        self.words.iter().map(|w| w.count_ones() as u64).sum()
    }

    /// The first pixel where two sets differ, if any.
    pub fn first_difference(&self, other: &Pixels) -> Option<[u32; 2]> {
        for j in 0..self.dims[1] {
            for i in 0..self.dims[0] {
                if self.get(i as i64, j as i64) != other.get(i as i64, j as i64) {
                    return Some([i, j]);
                }
            }
        }
        None
    }

    /// The ORs of two sets of the same dims.
    pub fn union_with(&mut self, other: &Pixels) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a |= b;
        }
    }
}

crate::choice! {
    /// A 2D rasterization mode.
    pub enum RasterMode: "raster mode" default Curve8 {
        /// 4-connected, 8-separating curves: the two pixel diagonals (Fig. 5c).
        Curve4 = "curve4",
        /// 8-connected, 4-separating curves: the crosshair (Fig. 7c).
        Curve8 = "curve8",
        /// The diamond (Fig. 7d): the rule graphics APIs use for lines.
        Diamond = "diamond",
        /// Filled shapes, each by its fill rule at the displaced pixel centre.
        Fill = "fill",
    }
}

crate::choice! {
    /// Which path rasterizes: the same pixels either way.
    pub enum RasterMethod: "raster method" default Fast {
        /// The fast path.
        Fast = "fast",
        /// Brute force from the definition.
        Reference = "reference",
    }
}

/// Rasterizes with the chosen method.
pub fn run(method: RasterMethod, mode: RasterMode, outlines: &[Outline], grid: &Grid2) -> (Pixels, RasterReport) {
    match method {
        RasterMethod::Fast => fast(mode, outlines, grid),
        RasterMethod::Reference => reference(mode, outlines, grid),
    }
}

/// The mode's fast path.
pub fn fast(mode: RasterMode, outlines: &[Outline], grid: &Grid2) -> (Pixels, RasterReport) {
    match mode {
        RasterMode::Fill => fill::fill(outlines, grid),
        m => curve::curve(m, outlines, grid),
    }
}

/// The mode's brute-force reference.
pub fn reference(mode: RasterMode, outlines: &[Outline], grid: &Grid2) -> (Pixels, RasterReport) {
    match mode {
        RasterMode::Fill => fill::reference::fill(outlines, grid),
        m => curve::reference::curve(m, outlines, grid),
    }
}
