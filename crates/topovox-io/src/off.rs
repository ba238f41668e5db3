//! Object File Format (`.off`), as Princeton's ModelNet and the Shape
//! Benchmark write it: an optional `OFF` keyword (`COFF`, `NOFF`, `CNOFF`,
//! `STOFF` name per-vertex extras, which are skipped), the counts
//! `vertices faces edges`, then one vertex per line (`x y z`, extras after)
//! and one face per line (`n i1 … in`, a colour after). Polygons are
//! fanned into triangles. `#` starts a comment; blank lines are skipped.
//! ModelNet's known quirk, the keyword run into the counts (`OFF490 518
//! 0`), is read as meant. Binary OFF is refused.
//!
//! Written by hand: no maintained crate reads OFF, and the format is a
//! few lines of text. The counts are checked against the lines there are,
//! never trusted for an allocation.

use glam::DVec3;

use crate::error::ErrorKind;
use crate::mesh_report::{finish, LoadedMesh};

fn bad(what: impl Into<String>) -> ErrorKind {
    ErrorKind::malformed("OFF", what.into())
}

/// Parses `.off` text.
pub fn read(bytes: &[u8]) -> Result<LoadedMesh, ErrorKind> {
    let text = std::str::from_utf8(bytes).map_err(|e| bad(format!("not UTF-8 text ({e})")))?;
    // Lines with content, numbered from 1, comments cut.
    let mut lines = text.lines().enumerate().map(|(n, l)| (n + 1, l.split('#').next().unwrap_or("").trim())).filter(|(_, l)| !l.is_empty());
    let (n, first) = lines.next().ok_or_else(|| bad("empty file"))?;
    let counts_line = match header(first) {
        Header::Keyword("") => lines.next().ok_or_else(|| bad("no counts after the OFF keyword"))?,
        Header::Keyword(rest) => (n, rest),
        Header::Binary => return Err(ErrorKind::Unsupported("binary OFF (write it as text)".into())),
        Header::Counts => (n, first),
    };
    let counts = numbers::<u64>(counts_line.1, counts_line.0)?;
    let [nv, nf] = match counts[..] {
        [v, f, ..] => [v, f],
        _ => return Err(bad(format!("line {}: expected the counts `vertices faces edges`", counts_line.0))),
    };
    let mut positions = Vec::new();
    for _ in 0..nv {
        let Some((n, l)) = lines.next() else {
            return Err(bad(format!("declares {nv} vertices, the file ends after {}", positions.len())));
        };
        let v = numbers::<f64>(l, n)?;
        if v.len() < 3 {
            return Err(bad(format!("line {n}: a vertex needs x y z, found {} numbers", v.len())));
        }
        positions.push(DVec3::new(v[0], v[1], v[2]));
    }
    let mut triangles = Vec::new();
    let mut warnings = Vec::new();
    for read in 0..nf {
        let Some((n, l)) = lines.next() else {
            return Err(bad(format!("declares {nf} faces, the file ends after {read}")));
        };
        face(l, n, &mut triangles, &mut warnings)?;
    }
    if let Some((n, _)) = lines.next() {
        warnings.push(format!("line {n} and after: more than the {nv} vertices and {nf} faces declared; ignored"));
    }
    finish(positions, triangles, warnings)
}

/// What the first line is.
enum Header<'a> {
    /// A keyword (`OFF`, `COFF`, …), and what follows it on the line.
    Keyword(&'a str),
    /// `OFF BINARY`.
    Binary,
    /// No keyword: the counts.
    Counts,
}

fn header(first: &str) -> Header<'_> {
    let keyword_len = first.find(|c: char| !c.is_ascii_alphabetic()).unwrap_or(first.len());
    let (word, rest) = first.split_at(keyword_len);
    if !word.to_ascii_uppercase().ends_with("OFF") {
        return Header::Counts;
    }
    let rest = rest.trim();
    if rest.eq_ignore_ascii_case("binary") {
        return Header::Binary;
    }
    Header::Keyword(rest)
}

/// The whitespace-separated numbers of a line.
fn numbers<T: std::str::FromStr>(line: &str, n: usize) -> Result<Vec<T>, ErrorKind> {
    line.split_whitespace().map(|w| w.parse::<T>().map_err(|_| bad(format!("line {n}: {:?} is not a number here", short(w))))).collect()
}

fn short(w: &str) -> &str {
    &w[..w.char_indices().nth(24).map_or(w.len(), |(i, _)| i)]
}

/// One face line, `k i1 … ik [colour]`, fanned into triangles.
fn face(line: &str, n: usize, triangles: &mut Vec<[i64; 3]>, warnings: &mut Vec<String>) -> Result<(), ErrorKind> {
    let mut words = line.split_whitespace();
    let k: usize =
        words.next().and_then(|w| w.parse().ok()).ok_or_else(|| bad(format!("line {n}: a face starts with its vertex count")))?;
    let idx: Vec<i64> = words
        .take(k)
        .map(|w| w.parse::<i64>().map_err(|_| bad(format!("line {n}: {:?} is not an index", short(w)))))
        .collect::<Result<_, _>>()?;
    if idx.len() < k {
        return Err(bad(format!("line {n}: a face of {k} vertices lists {}", idx.len())));
    }
    if k < 3 {
        if warnings.len() < 8 {
            warnings.push(format!("line {n}: a face of {k} vertices skipped"));
        }
        return Ok(());
    }
    triangles.extend((1..k - 1).map(|t| [idx[0], idx[t], idx[t + 1]]));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modelnet_files_with_and_without_the_header_quirk() {
        let body = "4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 1 2 255 0 0\n";
        for text in [format!("OFF\n{body}"), format!("OFF{body}"), format!("# made by hand\nCOFF\n\n{body}"), body.to_string()] {
            let m = read(text.as_bytes()).unwrap_or_else(|e| panic!("{text:?}: {e}"));
            assert_eq!(m.mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]], "{text:?}");
            assert_eq!(m.mesh.positions[2], DVec3::new(1.0, 1.0, 0.0));
        }
    }

    #[test]
    fn bad_files_say_what_and_where() {
        for (text, says) in [
            ("", "empty file"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n", "declares 3 vertices, the file ends after 2"),
            ("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "declares 2 faces, the file ends after 1"),
            ("OFF\n3 1 0\n0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n", "line 4: \"x\" is not a number"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "a face of 3 vertices lists 2"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "refers to vertex 7, but there are only 3"),
            ("OFF\n4000000000 1 0\n0 0 0\n", "declares 4000000000 vertices"),
            ("OFF BINARY\n", "binary OFF"),
        ] {
            let e = read(text.as_bytes()).unwrap_err().to_string();
            assert!(e.contains(says), "{text:?}: {e}");
        }
    }
}
