//! ASCII PLY payloads read in place: one entry per line, its properties
//! as whitespace-separated numbers in header order.
//!
//! Hand-written for the same reason as `ply_binary.rs`: `ply-rs-bw` (which
//! still parses every header) builds a map of named properties per entry,
//! and for ASCII runs a parser grammar on every line: 0.4 s for a 278 k-face
//! file, 5× Open3D. Here an element's lines are found first (one scan for
//! newlines), then parsed in pieces of [`PIECE`] lines on all threads and
//! joined in order. A line is split at spaces and tabs and only the
//! properties a mesh needs are parsed (`x y z`, a colour, the index list;
//! the others are counted, so a short line is an error); lines of
//! elements a mesh does not use are only counted. A `float` property is
//! parsed as `f32`, as the header says and as the reference reads it.
//! Errors name the line, the element and the entry; with several, the
//! first in the file, for any thread count. [`crate::ply::reference`] is
//! the reference the tests compare it with.

use glam::DVec3;
use ply_rs_bw::ply::{ElementDef, Header, PropertyType, ScalarType};
use rayon::prelude::*;

use crate::error::ErrorKind;
use crate::ply_payload::{channel, index_list, Lists, Payload, VertexLayout};

/// Lines per piece parsed on one thread.
const PIECE: usize = 8192;

/// Lines of one element, in pieces.
struct Block<'a> {
    /// Each piece's first entry and its bytes (`\n`-separated lines).
    pieces: Vec<(usize, &'a [u8])>,
    /// The file's line number of the element's first line.
    first_line: usize,
}

/// Takes the next `el.count` lines of `rest`, which starts at the file's
/// line `line`; advances both.
fn block<'a>(el: &ElementDef, rest: &mut &'a [u8], line: &mut usize) -> Result<Block<'a>, ErrorKind> {
    let body: &'a [u8] = rest;
    let mut pieces = Vec::with_capacity(el.count / PIECE + 1);
    let (mut start, mut taken, mut end) = (0, 0, 0);
    for nl in memchr::memchr_iter(b'\n', body).take(el.count) {
        taken += 1;
        end = nl + 1;
        if taken % PIECE == 0 {
            pieces.push((taken - PIECE, &body[start..nl]));
            start = end;
        }
    }
    if taken < el.count && end < body.len() {
        // The last line of the file, without its newline.
        taken += 1;
        end = body.len();
    }
    if taken < el.count {
        return Err(ErrorKind::malformed("PLY", format!("the file ends inside '{}' entry {taken} of {}", el.name, el.count)));
    }
    if start < end {
        // Its lines without the newline that ends the last (if any).
        let lines = &body[start..end];
        pieces.push(((taken - 1) / PIECE * PIECE, lines.strip_suffix(b"\n").unwrap_or(lines)));
    }
    let first_line = *line;
    *rest = &body[end..];
    *line += taken;
    Ok(Block { pieces, first_line })
}

impl<'a> Block<'a> {
    /// Parses every piece with `parse(first entry, lines)` on all threads;
    /// the results in order, or the first error in the file.
    fn parse<T: Send>(
        &self,
        el: &ElementDef,
        parse: impl Fn(&mut Entries<'a, '_>) -> Result<T, ErrorKind> + Sync,
    ) -> Result<Vec<T>, ErrorKind> {
        let one = |&(entry, bytes): &(usize, &'a [u8])| {
            parse(&mut Entries { lines: bytes.split(|&b| b == b'\n'), el, first_line: self.first_line, entry })
        };
        // One piece is parsed here: waking the thread pool costs more.
        let results: Vec<Result<T, ErrorKind>> =
            if self.pieces.len() < 2 { self.pieces.iter().map(one).collect() } else { self.pieces.par_iter().map(one).collect() };
        results.into_iter().collect()
    }
}

/// The lines of one piece, as entries.
struct Entries<'a, 'e> {
    lines: std::slice::Split<'a, u8, fn(&u8) -> bool>,
    el: &'e ElementDef,
    first_line: usize,
    /// The entry the next line holds.
    entry: usize,
}

impl<'a, 'e> Iterator for Entries<'a, 'e> {
    type Item = Words<'a, 'e>;
    fn next(&mut self) -> Option<Words<'a, 'e>> {
        let line = self.lines.next()?;
        let entry = self.entry;
        self.entry += 1;
        Some(Words { line: line.strip_suffix(b"\r").unwrap_or(line), el: self.el, line_number: self.first_line + entry, entry })
    }
}

/// One entry's numbers, in order.
struct Words<'a, 'e> {
    line: &'a [u8],
    el: &'e ElementDef,
    line_number: usize,
    entry: usize,
}

impl<'a> Words<'a, '_> {
    fn next(&mut self) -> Result<&'a [u8], ErrorKind> {
        let blank = |b: &u8| *b == b' ' || *b == b'\t';
        let start = self.line.iter().position(|b| !blank(b)).unwrap_or(self.line.len());
        let rest = &self.line[start..];
        let end = rest.iter().position(blank).unwrap_or(rest.len());
        self.line = &rest[end..];
        match &rest[..end] {
            [] => Err(self.bad("has too few numbers")),
            word => Ok(word),
        }
    }

    fn bad(&self, what: &str) -> ErrorKind {
        ErrorKind::malformed("PLY", format!("line {}: '{}' entry {} {what}", self.line_number, self.el.name, self.entry))
    }

    /// The next word as a value of type `t` (a `float` read as `f32`).
    fn number(&mut self, t: &ScalarType) -> Result<f64, ErrorKind> {
        let w = self.next()?;
        let v = match t {
            ScalarType::Float => std::str::from_utf8(w).ok().and_then(|s| s.parse::<f32>().ok()).map(f64::from),
            ScalarType::Double => std::str::from_utf8(w).ok().and_then(|s| s.parse::<f64>().ok()),
            _ => integer(w).map(|i| i as f64),
        };
        v.ok_or_else(|| self.not_a_number(w))
    }

    /// The next word as an integer (a list count or an index).
    fn integer(&mut self) -> Result<i64, ErrorKind> {
        let w = self.next()?;
        integer(w).ok_or_else(|| self.not_a_number(w))
    }

    fn not_a_number(&self, w: &[u8]) -> ErrorKind {
        let shown = String::from_utf8_lossy(&w[..w.len().min(24)]).into_owned();
        self.bad(&format!("has {shown:?} where a number belongs"))
    }

    /// A list's count.
    fn count(&mut self) -> Result<usize, ErrorKind> {
        let n = self.integer()?;
        usize::try_from(n).map_err(|_| self.bad(&format!("has a list of {n} items")))
    }

    /// Skips a list.
    fn skip_list(&mut self) -> Result<(), ErrorKind> {
        for _ in 0..self.count()? {
            self.next()?;
        }
        Ok(())
    }
}

/// A decimal integer: digits after an optional sign (std's parse past 18 digits).
fn integer(w: &[u8]) -> Option<i64> {
    let (negative, digits) = match w {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, w),
    };
    if digits.is_empty() || digits.len() > 18 {
        return std::str::from_utf8(w).ok()?.parse().ok();
    }
    let mut v: i64 = 0;
    for &d in digits {
        let d = d.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v * 10 + d as i64;
    }
    Some(if negative { -v } else { v })
}

/// Reads the payload `body` (the bytes after `end_header`, which ends the
/// file's line `header_lines`) of an ASCII file.
pub(crate) fn read(header: &Header, body: &[u8], header_lines: usize) -> Result<Payload, ErrorKind> {
    let mut out = Payload::default();
    if !header.elements.contains_key("vertex") {
        return Err(ErrorKind::malformed("PLY", "no 'vertex' element"));
    }
    let (mut rest, mut line) = (body, header_lines + 1);
    for (name, el) in &header.elements {
        let b = block(el, &mut rest, &mut line)?;
        match name.as_str() {
            "vertex" => vertices(el, &b, &mut out)?,
            "face" => {
                out.faces = true;
                if let Some(k) = index_list(el)? {
                    for (t, _) in lists(el, &b, k, true)? {
                        out.triangles.extend(t);
                    }
                }
            }
            "tristrips" => {
                let strips = out.strips.insert((Vec::new(), Vec::new()));
                if let Some(k) = index_list(el)? {
                    for (_, (items, lens)) in lists(el, &b, k, false)? {
                        strips.0.extend(items);
                        strips.1.extend(lens);
                    }
                }
            }
            // Counted by `block`, never parsed.
            _ => {}
        }
    }
    Ok(out)
}

/// The vertices of `el`, a line each.
fn vertices(el: &ElementDef, b: &Block<'_>, out: &mut Payload) -> Result<(), ErrorKind> {
    let layout = VertexLayout::of(el)?;
    // The properties to parse, by position; the others are only counted.
    let mut wanted = vec![false; el.properties.len()];
    for (i, _) in layout.xyz.iter().chain(layout.colour.iter().flatten()) {
        wanted[*i] = true;
    }
    let float = layout.float_colour();
    let pieces = b.parse(el, |entries| {
        let (mut positions, mut colours) = (Vec::with_capacity(PIECE), Vec::new());
        let mut values = vec![0.0; wanted.len()];
        for mut words in entries {
            for (k, p) in el.properties.values().enumerate() {
                match &p.data_type {
                    PropertyType::Scalar(t) if wanted[k] => values[k] = words.number(t)?,
                    PropertyType::Scalar(_) => _ = words.next()?,
                    PropertyType::List(..) => words.skip_list()?,
                }
            }
            let xyz = &layout.xyz;
            positions.push(DVec3::new(values[xyz[0].0], values[xyz[1].0], values[xyz[2].0]));
            if let Some(c) = &layout.colour {
                colours.push([0, 1, 2].map(|k| channel(values[c[k].0], float)));
            }
        }
        Ok((positions, colours))
    })?;
    out.positions.reserve(el.count);
    for (p, c) in pieces {
        out.positions.extend(p);
        out.colours.extend(c);
    }
    Ok(())
}

/// Each piece's lists of the property at `keep`: fanned into triangles, or
/// kept flat with their lengths.
type PieceLists = (Vec<[i64; 3]>, (Vec<i64>, Vec<u32>));

/// The list property at `keep` of every entry of `el`, per piece.
fn lists(el: &ElementDef, b: &Block<'_>, keep: usize, fanned: bool) -> Result<Vec<PieceLists>, ErrorKind> {
    b.parse(el, |entries| {
        let mut out: PieceLists = Default::default();
        let mut lists = if fanned { Lists::Fanned(&mut out.0) } else { Lists::Flat(&mut out.1) };
        lists.reserve(PIECE);
        let mut list = Vec::new();
        for mut words in entries {
            for (k, p) in el.properties.values().enumerate() {
                match &p.data_type {
                    PropertyType::List(..) if k == keep => {
                        list.clear();
                        for _ in 0..words.count()? {
                            list.push(words.integer()?);
                        }
                        lists.push(&list);
                    }
                    PropertyType::Scalar(_) => _ = words.next()?,
                    PropertyType::List(..) => words.skip_list()?,
                }
            }
        }
        Ok(out)
    })
}
