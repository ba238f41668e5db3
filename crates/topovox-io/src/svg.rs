//! SVG input for `topovox raster`: outlines in the plane, through the
//! `roxmltree` (XML) and `svgtypes` (path data, points, transforms) crates.
//!
//! Read: `<path d>` (every command: `M L H V Z` absolute and relative;
//! `C S Q T A` curves and arcs are flattened, below), `<polyline>`,
//! `<polygon>`, `<line>`, `<rect>` (square corners), `<circle>` and
//! `<ellipse>` (flattened), each with the `transform`s of the element and
//! its ancestors applied. Elements inside `<defs>`, `<clipPath>`,
//! `<mask>`, `<marker>`, `<pattern>` and `<symbol>` are not drawn and are
//! skipped; `<use>`, rounded rectangles and lengths with units other than
//! `px` are refused with an error naming them (never drawn wrongly);
//! `<text>` and `<image>` are skipped with a warning.
//!
//! **Painting.** Each element is one shape for `raster --mode fill`, filled
//! as SVG paints it: its `fill` (a presentation attribute or a `style`
//! declaration, the declaration winning; inherited from the enclosing
//! groups; black, so filled, by default) and its `fill-rule` (`nonzero` by
//! default, or `evenodd`) decide; a `<path>`'s subpaths are filled together,
//! each closed. `fill="none"` leaves the element unfilled: `fill` ignores
//! it, and the curve modes (`curve4`, `curve8`, `diamond`) draw it like
//! every other element, whatever its `fill` and `stroke`. Stroke widths are
//! not drawn (a curve is the outline itself), and `<style>` sheets are not
//! applied (a warning says so when one sets `fill`).
//!
//! Coordinates: SVG user units are the plane's coordinates (`x → i`,
//! `y → j`, no flip). **Flattening:** curves are split until every chord
//! lies within the tolerance of the curve (`tolerance`, in user units;
//! default `1e-5` × the drawing's extent, well under a pixel at any
//! resolution topovox allows).

use glam::DVec2;
use topovox::choice::Choice;
use topovox::raster::{FillRule, Outline};

use crate::error::ErrorKind;

/// How an SVG is read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SvgOptions {
    /// Largest distance of a flattened chord from its curve, in user units
    /// (default: `1e-5` × the drawing's extent).
    pub tolerance: Option<f64>,
}

/// Outlines read from an SVG, and warnings.
#[derive(Clone, Debug, Default)]
pub struct LoadedSvg {
    /// Polylines (closed by `Z`, `<polygon>`, `<rect>`, circles, ellipses),
    /// each with its element's fill rule (`None`: `fill="none"`) and the
    /// element's number as its shape.
    pub outlines: Vec<Outline>,
    /// Skipped elements.
    pub warnings: Vec<String>,
}

/// A path in user units before flattening.
#[derive(Clone, Debug)]
enum Piece {
    Move(DVec2),
    Line(DVec2),
    Cubic(DVec2, DVec2, DVec2),
    Close,
}

/// One element's path and how it is filled.
struct Element {
    pieces: Vec<Piece>,
    fill: Option<FillRule>,
}

/// The fill properties an element inherits and passes on.
#[derive(Clone, Copy)]
struct Painting {
    filled: bool,
    rule: FillRule,
}

impl Painting {
    /// SVG's initial values: filled (black), nonzero.
    const INITIAL: Painting = Painting { filled: true, rule: FillRule::NonZero };

    /// The node's own painting: its presentation attributes, then its
    /// `style` declarations, over what it inherits. Values a browser would
    /// ignore (unparsable) are ignored here too.
    fn of(self, node: roxmltree::Node<'_, '_>) -> Painting {
        let attributes = ["fill", "fill-rule"].into_iter().filter_map(|n| node.attribute(n).map(|v| (n, v)));
        let style = node.attribute("style").unwrap_or("").split(';').filter_map(|d| d.split_once(':'));
        let mut out = self;
        for (name, value) in attributes.chain(style) {
            let value = value.trim().trim_end_matches("!important").trim();
            match name.trim() {
                "fill" => match svgtypes::Paint::from_str(value) {
                    Ok(svgtypes::Paint::None) => out.filled = false,
                    Ok(svgtypes::Paint::Inherit) => out.filled = self.filled,
                    Ok(_) => out.filled = true,
                    Err(_) => {}
                },
                "fill-rule" if value == "inherit" => out.rule = self.rule,
                "fill-rule" => out.rule = FillRule::parse(value).unwrap_or(out.rule),
                _ => {}
            }
        }
        out
    }

    fn fill(self) -> Option<FillRule> {
        self.filled.then_some(self.rule)
    }
}

#[derive(Clone, Copy)]
struct Affine([f64; 6]);

impl Affine {
    const ID: Affine = Affine([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);

    fn then(self, inner: Affine) -> Affine {
        // self ∘ inner: parent transform applied after the child's.
        let [a, b, c, d, e, f] = self.0;
        let [a2, b2, c2, d2, e2, f2] = inner.0;
        Affine([a * a2 + c * b2, b * a2 + d * b2, a * c2 + c * d2, b * c2 + d * d2, a * e2 + c * f2 + e, b * e2 + d * f2 + f])
    }

    fn apply(self, p: DVec2) -> DVec2 {
        let [a, b, c, d, e, f] = self.0;
        DVec2::new(a * p.x + c * p.y + e, b * p.x + d * p.y + f)
    }
}

/// Parses SVG bytes into outlines.
pub fn read(bytes: &[u8], opts: &SvgOptions) -> Result<LoadedSvg, ErrorKind> {
    let text = std::str::from_utf8(bytes).map_err(|e| ErrorKind::malformed("SVG", format!("not UTF-8 ({e})")))?;
    let doc = roxmltree::Document::parse(text).map_err(|e| ErrorKind::malformed("SVG", e))?;
    check_depth(&doc)?;
    let mut paths: Vec<Element> = Vec::new();
    let mut warnings = Vec::new();
    walk(doc.root_element(), (Affine::ID, Painting::INITIAL), &mut paths, &mut warnings)?;
    // The drawing's extent (end and control points) sets the default tolerance.
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in paths.iter().flat_map(|e| &e.pieces) {
        let pts: &[DVec2] = match p {
            Piece::Move(a) | Piece::Line(a) => std::slice::from_ref(a),
            Piece::Cubic(a, b, c) => &[*a, *b, *c][..],
            Piece::Close => &[],
        };
        for q in pts {
            lo = lo.min(*q);
            hi = hi.max(*q);
        }
    }
    let extent = (hi - lo).max_element();
    let tol = match opts.tolerance {
        Some(t) if t.is_finite() && t > 0.0 => t,
        Some(t) => return Err(ErrorKind::malformed("SVG", format!("tolerance must be a positive number, got {t}"))),
        None if extent.is_finite() && extent > 0.0 => extent * 1e-5,
        None => 1e-9,
    };
    let mut outlines = Vec::new();
    let mut total = 0usize;
    for (shape, Element { pieces, fill }) in paths.into_iter().enumerate() {
        let first = outlines.len();
        let mut cur = Outline::default();
        let mut at = DVec2::ZERO;
        let mut start = DVec2::ZERO;
        let push = |o: &mut Outline, out: &mut Vec<Outline>| {
            if o.points.len() >= 2 {
                out.push(std::mem::take(o));
            } else {
                o.points.clear();
                o.closed = false;
            }
        };
        for p in pieces {
            match p {
                Piece::Move(a) => {
                    push(&mut cur, &mut outlines);
                    cur.points.push(a);
                    (at, start) = (a, a);
                }
                Piece::Line(a) => {
                    if cur.points.is_empty() {
                        cur.points.push(at);
                    }
                    cur.points.push(a);
                    at = a;
                }
                Piece::Cubic(c1, c2, a) => {
                    if cur.points.is_empty() {
                        cur.points.push(at);
                    }
                    let before = cur.points.len();
                    flatten_cubic(at, c1, c2, a, tol, 0, &mut cur.points);
                    at = a;
                    total += cur.points.len() - before;
                    if total > MAX_POINTS {
                        return Err(ErrorKind::malformed(
                            "SVG",
                            format!("flattening the curves needs more than {MAX_POINTS} points at tolerance {tol}; raise --tolerance"),
                        ));
                    }
                }
                Piece::Close => {
                    cur.closed = true;
                    if cur.points.last() == Some(&start) && cur.points.len() > 1 {
                        cur.points.pop();
                    }
                    push(&mut cur, &mut outlines);
                    at = start;
                }
            }
        }
        push(&mut cur, &mut outlines);
        for o in &mut outlines[first..] {
            (o.fill, o.shape) = (fill, shape.min(u32::MAX as usize) as u32);
        }
    }
    if outlines.iter().all(|o| o.points.is_empty()) {
        return Err(ErrorKind::malformed("SVG", "no path, polyline, polygon, line, rect, circle or ellipse with at least two points"));
    }
    for (n, o) in outlines.iter().enumerate() {
        if let Some(p) = o.points.iter().find(|p| !p.is_finite()) {
            return Err(ErrorKind::malformed("SVG", format!("outline {n} has a non-finite point {p}")));
        }
    }
    Ok(LoadedSvg { outlines, warnings })
}

/// Largest magnitude of a number in path data. Arcs become cubics inside
/// `svgtypes`, which splits an arc more finely the larger it is against a
/// fixed tolerance: an arc to 1e110 took minutes (found by fuzzing).
const MAX_PATH_NUMBER: f64 = 1e12;

/// Refuses path data holding a number beyond [`MAX_PATH_NUMBER`].
fn check_path_numbers(d: &str) -> Result<(), ErrorKind> {
    use svgtypes::PathSegment as P;
    for seg in svgtypes::PathParser::from(d) {
        let Ok(seg) = seg else { break }; // the simplifying parser reports it
        let nums: &[f64] = match &seg {
            P::MoveTo { x, y, .. } | P::LineTo { x, y, .. } | P::SmoothQuadratic { x, y, .. } => &[*x, *y],
            P::HorizontalLineTo { x, .. } => &[*x],
            P::VerticalLineTo { y, .. } => &[*y],
            P::CurveTo { x1, y1, x2, y2, x, y, .. } => &[*x1, *y1, *x2, *y2, *x, *y],
            P::SmoothCurveTo { x2, y2, x, y, .. } => &[*x2, *y2, *x, *y],
            P::Quadratic { x1, y1, x, y, .. } => &[*x1, *y1, *x, *y],
            P::EllipticalArc { rx, ry, x, y, .. } => &[*rx, *ry, *x, *y],
            P::ClosePath { .. } => &[],
        };
        if let Some(v) = nums.iter().find(|v| v.is_nan() || v.abs() > MAX_PATH_NUMBER) {
            return Err(ErrorKind::malformed("SVG", format!("<path> d: number {v} beyond {MAX_PATH_NUMBER:e}")));
        }
    }
    Ok(())
}

/// Most points the flattened curves of one file may have (a hostile file's
/// curves at a tiny tolerance would otherwise take minutes and gigabytes).
const MAX_POINTS: usize = 1 << 24;

/// Appends the points after `p0` of the cubic `p0 c1 c2 p3`, split until
/// the control points lie within `tol` of the chord.
fn flatten_cubic(p0: DVec2, c1: DVec2, c2: DVec2, p3: DVec2, tol: f64, depth: u32, out: &mut Vec<DVec2>) {
    let chord = p3 - p0;
    let len = chord.length();
    let dist = |q: DVec2| if len > 0.0 { (q - p0).perp_dot(chord).abs() / len } else { (q - p0).length() };
    // A non-finite point ends the split (the outline is refused below).
    let finite = p0.is_finite() && c1.is_finite() && c2.is_finite() && p3.is_finite();
    if depth >= 24 || !finite || (dist(c1) <= tol && dist(c2) <= tol) {
        out.push(p3);
        return;
    }
    let (m01, m12, m23) = ((p0 + c1) * 0.5, (c1 + c2) * 0.5, (c2 + p3) * 0.5);
    let (a, b) = ((m01 + m12) * 0.5, (m12 + m23) * 0.5);
    let mid = (a + b) * 0.5;
    flatten_cubic(p0, m01, a, mid, tol, depth + 1, out);
    flatten_cubic(mid, b, m23, p3, tol, depth + 1, out);
}

fn number(node: roxmltree::Node<'_, '_>, name: &str, default: f64) -> Result<f64, ErrorKind> {
    let Some(v) = node.attribute(name) else { return Ok(default) };
    let l: svgtypes::Length = v
        .parse()
        .map_err(|e| ErrorKind::malformed("SVG", format!("<{}> {name}={}: {e}", node.tag_name().name(), crate::error::quoted(v))))?;
    match l.unit {
        svgtypes::LengthUnit::None | svgtypes::LengthUnit::Px => Ok(l.number),
        u => Err(ErrorKind::Unsupported(format!(
            "<{}> {name}={}: unit {u:?} (give plain numbers or px)",
            node.tag_name().name(),
            crate::error::quoted(v)
        ))),
    }
}

/// How deeply elements may nest: [`walk`] recurses once per level, and a
/// few kilobytes of SVG can nest thousands of `<g>` (a stack overflow).
/// Drawings nest a few dozen deep.
const MAX_DEPTH: usize = 512;

/// Refuses a document nesting elements deeper than [`MAX_DEPTH`], found
/// without recursion: the open elements of a walk in document order.
fn check_depth(doc: &roxmltree::Document<'_>) -> Result<(), ErrorKind> {
    let mut open: Vec<roxmltree::Node<'_, '_>> = Vec::new();
    for n in doc.descendants().filter(|n| n.is_element()) {
        while open.last().is_some_and(|&last| Some(last) != n.parent()) {
            open.pop();
        }
        open.push(n);
        if open.len() > MAX_DEPTH {
            return Err(ErrorKind::malformed("SVG", format!("elements nested more than {MAX_DEPTH} deep")));
        }
    }
    Ok(())
}

/// A `<path>`'s `d` as pieces, each point mapped by `p`.
fn path_pieces(d: &str, p: &impl Fn(f64, f64) -> DVec2) -> Result<Vec<Piece>, ErrorKind> {
    check_path_numbers(d)?;
    let mut pieces = Vec::new();
    // The current point and the subpath's start, in plane coordinates.
    let (mut at, mut start) = (DVec2::ZERO, DVec2::ZERO);
    for seg in svgtypes::SimplifyingPathParser::from(d) {
        let seg = seg.map_err(|e| ErrorKind::malformed("SVG", format!("<path> d: {e}")))?;
        use svgtypes::SimplePathSegment as S;
        let piece = match seg {
            S::MoveTo { x, y } => {
                start = p(x, y);
                Piece::Move(start)
            }
            S::LineTo { x, y } => Piece::Line(p(x, y)),
            S::CurveTo { x1, y1, x2, y2, x, y } => Piece::Cubic(p(x1, y1), p(x2, y2), p(x, y)),
            S::Quadratic { x1, y1, x, y } => {
                // Elevated to a cubic from the current point.
                let (q, end) = (p(x1, y1), p(x, y));
                Piece::Cubic(at + (q - at) * (2.0 / 3.0), end + (q - end) * (2.0 / 3.0), end)
            }
            S::ClosePath => Piece::Close,
        };
        at = match &piece {
            Piece::Move(a) | Piece::Line(a) | Piece::Cubic(_, _, a) => *a,
            Piece::Close => start,
        };
        pieces.push(piece);
    }
    Ok(pieces)
}

/// An ellipse of centre `c` and radii `r` as four cubic quarter arcs
/// (kappa = 0.5523), flattened like paths; points mapped by `p`.
fn ellipse_pieces(c: DVec2, r: DVec2, p: &impl Fn(f64, f64) -> DVec2) -> Vec<Piece> {
    let k = 0.552_284_749_830_793_4;
    let (cx, cy, rx, ry) = (c.x, c.y, r.x, r.y);
    let q = |ax: f64, ay: f64| p(cx + ax, cy + ay);
    vec![
        Piece::Move(q(rx, 0.0)),
        Piece::Cubic(q(rx, k * ry), q(k * rx, ry), q(0.0, ry)),
        Piece::Cubic(q(-k * rx, ry), q(-rx, k * ry), q(-rx, 0.0)),
        Piece::Cubic(q(-rx, -k * ry), q(-k * rx, -ry), q(0.0, -ry)),
        Piece::Cubic(q(k * rx, -ry), q(rx, -k * ry), q(rx, 0.0)),
        Piece::Close,
    ]
}

/// Reads the drawn elements under `node`, with the transform and painting
/// its parent passes on.
fn walk(
    node: roxmltree::Node<'_, '_>,
    (parent, painting): (Affine, Painting),
    elements: &mut Vec<Element>,
    warnings: &mut Vec<String>,
) -> Result<(), ErrorKind> {
    if !node.is_element() {
        return Ok(());
    }
    let name = node.tag_name().name();
    if name == "style" && node.text().is_some_and(|t| t.contains("fill")) {
        warnings.push("a <style> sheet sets fill; style sheets are not applied (use fill= or style= on the elements)".into());
    }
    if matches!(name, "defs" | "clipPath" | "mask" | "marker" | "pattern" | "symbol" | "metadata" | "title" | "desc" | "style") {
        return Ok(());
    }
    let painting = painting.of(node);
    let mut out = Vec::new();
    let local = match node.attribute("transform") {
        Some(t) => {
            let ts: svgtypes::Transform =
                t.parse().map_err(|e| ErrorKind::malformed("SVG", format!("<{name}> transform={}: {e}", crate::error::quoted(t))))?;
            Affine([ts.a, ts.b, ts.c, ts.d, ts.e, ts.f])
        }
        None => Affine::ID,
    };
    let m = parent.then(local);
    let p = |x: f64, y: f64| m.apply(DVec2::new(x, y));
    match name {
        "path" => out.push(path_pieces(node.attribute("d").unwrap_or(""), &p)?),
        "polyline" | "polygon" => {
            let pts: Vec<DVec2> = svgtypes::PointsParser::from(node.attribute("points").unwrap_or("")).map(|(x, y)| p(x, y)).collect();
            let mut pieces: Vec<Piece> =
                pts.iter().enumerate().map(|(i, &q)| if i == 0 { Piece::Move(q) } else { Piece::Line(q) }).collect();
            if name == "polygon" {
                pieces.push(Piece::Close);
            }
            out.push(pieces);
        }
        "line" => {
            let (x1, y1, x2, y2) = (number(node, "x1", 0.0)?, number(node, "y1", 0.0)?, number(node, "x2", 0.0)?, number(node, "y2", 0.0)?);
            out.push(vec![Piece::Move(p(x1, y1)), Piece::Line(p(x2, y2))]);
        }
        "rect" => {
            if number(node, "rx", 0.0)? != 0.0 || number(node, "ry", 0.0)? != 0.0 {
                return Err(ErrorKind::Unsupported("<rect> with rounded corners (rx/ry); draw it as a <path>".into()));
            }
            let (x, y, w, h) =
                (number(node, "x", 0.0)?, number(node, "y", 0.0)?, number(node, "width", 0.0)?, number(node, "height", 0.0)?);
            out.push(vec![
                Piece::Move(p(x, y)),
                Piece::Line(p(x + w, y)),
                Piece::Line(p(x + w, y + h)),
                Piece::Line(p(x, y + h)),
                Piece::Close,
            ]);
        }
        "circle" | "ellipse" => {
            let (cx, cy) = (number(node, "cx", 0.0)?, number(node, "cy", 0.0)?);
            let (rx, ry) = if name == "circle" {
                let r = number(node, "r", 0.0)?;
                (r, r)
            } else {
                (number(node, "rx", 0.0)?, number(node, "ry", 0.0)?)
            };
            out.push(ellipse_pieces(DVec2::new(cx, cy), DVec2::new(rx, ry), &p));
        }
        "use" => return Err(ErrorKind::Unsupported("<use> references (inline the referenced shapes)".into())),
        "text" | "image" | "foreignObject" => warnings.push(format!("<{name}> is not an outline; skipped")),
        _ => {}
    }
    elements.extend(out.into_iter().map(|pieces| Element { pieces, fill: painting.fill() }));
    for child in node.children() {
        walk(child, (m, painting), elements, warnings)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outlines(svg: &str) -> Vec<Outline> {
        read(svg.as_bytes(), &SvgOptions::default()).unwrap().outlines
    }

    #[test]
    fn path_commands_absolute_and_relative() {
        let o = outlines(r#"<svg><path d="M 1 2 L 5 2 l 0 3 H 1 v -1 Z m 10 0 h 2"/></svg>"#);
        assert_eq!(o.len(), 2);
        assert!(o[0].closed);
        assert_eq!(o[0].points, vec![DVec2::new(1., 2.), DVec2::new(5., 2.), DVec2::new(5., 5.), DVec2::new(1., 5.), DVec2::new(1., 4.)]);
        assert_eq!(o[1].points, vec![DVec2::new(11., 2.), DVec2::new(13., 2.)]);
        assert!(!o[1].closed);
    }

    #[test]
    fn transforms_compose_and_shapes_close() {
        let o = outlines(
            r#"<svg><g transform="translate(10 0)"><polygon points="0,0 1,0 0,1" transform="scale(2)"/></g><polyline points="0 0 3 3"/></svg>"#,
        );
        assert_eq!(o[0].points, vec![DVec2::new(10., 0.), DVec2::new(12., 0.), DVec2::new(10., 2.)]);
        assert!(o[0].closed && !o[1].closed);
    }

    #[test]
    fn deep_nesting_is_refused_not_a_stack_overflow() {
        // Issue 54: 9,000 nested <g> (63 KB) overflowed the stack.
        let deep = |n: usize| format!("<svg>{}<path d=\"M0 0 L1 0 L0 1 Z\"/>{}</svg>", "<g>".repeat(n), "</g>".repeat(n));
        let e = read(deep(9000).as_bytes(), &SvgOptions::default()).unwrap_err().to_string();
        assert!(e.contains("nested more than 512 deep"), "{e}");
        assert_eq!(outlines(&deep(MAX_DEPTH - 2)).len(), 1);
    }

    #[test]
    fn huge_arcs_end_quickly() {
        // Fuzzing found this: arcs to 1e31 and 1e110 split to the depth
        // limit on every piece (non-finite distances), for minutes.
        let svg = br#"<svg><path d="M0 8 L4 4 h3 v-3 z m1 1 c 1 1 2 2 3 0 s 1 1 2 2 q 1 1 2 0 t 0 1 a 2 2 0 0 1 99999999999999999999999999999992 3 0 s 1 1 2 2 q 1 1 2 0 t 0 1 a 2 2 0 0 1 9999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999993 3"/></svg>"#;
        let t = std::time::Instant::now();
        let _ = read(svg, &SvgOptions::default());
        assert!(t.elapsed().as_secs_f64() < 5.0, "took {:?}", t.elapsed());
        let tiny = br#"<svg><circle cx="0" cy="0" r="10"/></svg>"#;
        assert!(read(tiny, &SvgOptions { tolerance: Some(1e-300) }).is_err());
    }

    #[test]
    fn curves_are_flattened_within_the_tolerance() {
        let o = read(br#"<svg><circle cx="0" cy="0" r="10"/></svg>"#, &SvgOptions { tolerance: Some(0.01) }).unwrap().outlines;
        assert!(o[0].points.len() > 40, "{}", o[0].points.len());
        // Chords within 0.01 plus the cubic's own error (~0.0003 r) of the circle.
        for w in o[0].points.windows(2) {
            let mid = (w[0] + w[1]) * 0.5;
            assert!((mid.length() - 10.0).abs() < 0.015, "{}", mid.length());
        }
        let arc = outlines(r#"<svg><path d="M 0 0 A 5 5 0 0 1 10 0"/></svg>"#);
        assert!(arc[0].points.len() > 8);
    }

    #[test]
    fn fill_and_fill_rule_are_read_inherited_and_overridden() {
        let o = outlines(
            r#"<svg><style>.a { fill: red }</style>
            <polygon points="0,0 1,0 0,1"/>
            <g fill="none" style="fill-rule: evenodd">
              <polyline points="0,0 5,5 9,0"/>
              <path d="M0 0 h4 v4 z M1 1 h2 v2 z" fill="blue"/>
              <rect width="2" height="2" style="stroke: black; fill : #00f !important" fill="none"/>
              <circle r="2" fill="inherit" style="fill-rule:nonzero"/>
              <line x2="3" fill="bogus(" />
            </g></svg>"#,
        );
        let fills: Vec<_> = o.iter().map(|o| (o.fill, o.shape)).collect();
        let (nz, eo) = (Some(FillRule::NonZero), Some(FillRule::EvenOdd));
        assert_eq!(fills, [(nz, 0), (None, 1), (eo, 2), (eo, 2), (eo, 3), (None, 4), (None, 5)]);
        let w = read(br#"<svg><style>path { fill: none }</style><path d="M0 0 L1 1"/></svg>"#, &SvgOptions::default()).unwrap();
        assert!(w.warnings.iter().any(|w| w.contains("style sheets are not applied")), "{:?}", w.warnings);
    }

    #[test]
    fn unsupported_input_is_an_error() {
        for svg in [
            r##"<svg><use href="#a"/></svg>"##,
            r#"<svg><rect width="1" height="1" rx="0.2"/></svg>"#,
            r#"<svg><line x2="1cm"/></svg>"#,
            "<svg/>",
            "not xml",
        ] {
            assert!(read(svg.as_bytes(), &SvgOptions::default()).is_err(), "{svg}");
        }
    }
}
