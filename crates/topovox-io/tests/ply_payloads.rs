//! The in-place PLY readers (binary and ASCII) equal `ply-rs-bw`'s (the
//! reference), value for value, on every layout a file may have: both
//! endiannesses and ASCII (spaces, tabs, CRLF), every scalar type,
//! properties before and after the coordinates, colours as bytes or
//! floats, polygons and triangle strips, other elements with lists between
//! them, elements longer than one parallel piece, and every truncation
//! (both readers refuse it).

use topovox_io::ply::{read, reference};

/// A small deterministic generator (no dependency).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 31) as f64
    }
}

#[derive(Clone, Copy)]
struct Layout {
    big: bool,
    /// "float" or "double" coordinates.
    double: bool,
    /// A scalar property before x.
    before: bool,
    /// Colour as "uchar" bytes, "float", or none.
    colour: Option<bool>,
    /// The list's count and index types.
    count: &'static str,
    index: &'static str,
    /// An element with a list between vertex and face.
    between: bool,
    /// Triangle strips instead of faces.
    strips: bool,
    /// ASCII, with this separator between numbers and this line end.
    ascii: Option<(&'static str, &'static str)>,
    /// A property after the index list (else the list alone: the fast path).
    flags: bool,
}

/// Writes entries as a layout's encoding: binary scalars, or numbers
/// separated and lines ended as its ASCII asks.
struct Out {
    bytes: Vec<u8>,
    big: bool,
    ascii: Option<(&'static str, &'static str)>,
}

impl Out {
    fn put(&mut self, ty: &str, v: f64) {
        match self.ascii {
            None => put(&mut self.bytes, ty, v, self.big),
            Some((sep, _)) => {
                let text = match ty {
                    "float" => format!("{}", v as f32),
                    "double" => format!("{v}"),
                    _ => format!("{}", v as i64),
                };
                self.bytes.extend(text.as_bytes());
                self.bytes.extend(sep.as_bytes());
            }
        }
    }

    /// Ends an entry (its line, in ASCII).
    fn end(&mut self) {
        if let Some((sep, eol)) = self.ascii {
            self.bytes.truncate(self.bytes.len() - sep.len());
            self.bytes.extend(eol.as_bytes());
        }
    }
}

fn put(out: &mut Vec<u8>, ty: &str, v: f64, big: bool) {
    macro_rules! w {
        ($t:ty) => {{
            let x = v as $t;
            out.extend(if big { x.to_be_bytes().to_vec() } else { x.to_le_bytes().to_vec() });
        }};
    }
    match ty {
        "char" => w!(i8),
        "uchar" => w!(u8),
        "short" => w!(i16),
        "ushort" => w!(u16),
        "int" => w!(i32),
        "uint" => w!(u32),
        "float" => w!(f32),
        _ => w!(f64),
    }
}

fn file(l: Layout, vertices: usize, faces: usize, seed: u64) -> Vec<u8> {
    let mut r = Lcg(seed);
    let enc = match (l.ascii, l.big) {
        (Some(_), _) => "ascii",
        (None, true) => "binary_big_endian",
        (None, false) => "binary_little_endian",
    };
    let coord = if l.double { "double" } else { "float" };
    let mut h = format!("ply\nformat {enc} 1.0\ncomment made by a test\nelement vertex {vertices}\n");
    if l.before {
        h += "property short quality\n";
    }
    h += &format!("property {coord} x\nproperty {coord} y\nproperty {coord} z\n");
    match l.colour {
        Some(true) => h += "property uchar red\nproperty uchar green\nproperty uchar blue\n",
        Some(false) => h += "property float r\nproperty float g\nproperty float b\n",
        None => {}
    }
    if l.between {
        h += "element edge 2\nproperty int vertex1\nproperty list uchar int extra\n";
    }
    let (el, list) = if l.strips { ("tristrips", "vertex_indices") } else { ("face", "vertex_indices") };
    h += &format!("element {el} {faces}\nproperty list {} {} {list}\n", l.count, l.index);
    h += if l.flags { "property uchar flags\nend_header\n" } else { "end_header\n" };
    let mut out = Out { bytes: h.into_bytes(), big: l.big, ascii: l.ascii };
    for _ in 0..vertices {
        if l.before {
            out.put("short", (r.next() % 100) as f64);
        }
        for _ in 0..3 {
            out.put(coord, r.unit() * 8.0 - 4.0);
        }
        match l.colour {
            Some(true) => (0..3).for_each(|_| out.put("uchar", (r.next() % 256) as f64)),
            Some(false) => (0..3).for_each(|_| out.put("float", r.unit() * 1.2 - 0.1)),
            None => {}
        }
        out.end();
    }
    if l.between {
        for e in 0..2 {
            out.put("int", e as f64);
            out.put("uchar", 2.0);
            out.put("int", 7.0);
            out.put("int", 8.0);
            out.end();
        }
    }
    let max_index = match l.index {
        "uchar" | "char" => vertices.min(100),
        _ => vertices,
    };
    for _ in 0..faces {
        let n = if l.strips { 3 + r.next() % 6 } else { 3 + r.next() % 3 };
        out.put(l.count, n as f64);
        for k in 0..n {
            let v = if l.strips && k == 3 && r.next() % 4 == 0 { -1.0 } else { (r.next() % max_index as u64) as f64 };
            let v = if l.index.starts_with('u') && v < 0.0 { 0.0 } else { v };
            out.put(l.index, v);
        }
        if l.flags {
            out.put("uchar", 1.0);
        }
        out.end();
    }
    out.bytes
}

fn layouts() -> Vec<Layout> {
    let mut v = Vec::new();
    let ascii = [None, Some((" ", "\n")), Some(("\t ", "\r\n"))];
    for (big, ascii) in [(false, ascii[0]), (true, ascii[0]), (false, ascii[1]), (false, ascii[2])] {
        for (double, before, colour) in
            [(false, false, None), (true, true, Some(true)), (false, true, Some(false)), (true, false, Some(true))]
        {
            for (count, index) in
                [("uchar", "int"), ("uchar", "uint"), ("ushort", "int"), ("int", "uint"), ("uchar", "ushort"), ("char", "short")]
            {
                for (between, strips, flags) in [(false, false, true), (false, false, false), (true, false, true), (false, true, true)] {
                    v.push(Layout { big, double, before, colour, count, index, between, strips, ascii, flags });
                }
            }
        }
    }
    v
}

fn same(bytes: &[u8], what: &str) {
    match (read(bytes), reference::read(bytes)) {
        (Ok(a), Ok(b)) => {
            assert_eq!(a.mesh, b.mesh, "{what}");
            assert_eq!(a.appearance.vertex_colour, b.appearance.vertex_colour, "{what}");
            assert_eq!(a.report, b.report, "{what}");
        }
        (Err(_), Err(_)) => {}
        (a, b) => panic!("{what}: in place {:?}, reference {:?}", a.map(|m| m.mesh.triangles.len()), b.map(|m| m.mesh.triangles.len())),
    }
}

#[test]
fn every_layout_reads_as_the_reference_reads_it() {
    for (n, l) in layouts().into_iter().enumerate() {
        let bytes = file(l, 300, 500, n as u64);
        assert!(read(&bytes).is_ok(), "layout {n}: {:?}", read(&bytes).err());
        same(&bytes, &format!("layout {n}"));
    }
}

/// A little-endian layout with every part a file may have (a property
/// before the coordinates, byte colours, an element between), a property
/// after the index list in binary, the list alone in ASCII.
fn every_part(ascii: Option<(&'static str, &'static str)>) -> Layout {
    Layout {
        big: false,
        double: false,
        before: true,
        colour: Some(true),
        count: "uchar",
        index: "int",
        between: true,
        strips: false,
        ascii,
        flags: ascii.is_none(),
    }
}

#[test]
fn long_elements_read_in_pieces_as_the_reference_reads_them() {
    // More lines than one parallel piece (8192), and a last line without its newline.
    for ascii in [Some((" ", "\n")), Some(("\t", "\r\n")), None] {
        let l = every_part(ascii);
        let mut bytes = file(l, 20_000, 40_000, 11);
        same(&bytes, "long");
        if ascii.is_some() {
            while bytes.last().is_some_and(|b| b.is_ascii_whitespace()) {
                bytes.pop();
            }
            assert!(read(&bytes).is_ok(), "{:?}", read(&bytes).err());
            same(&bytes, "long, no newline at the end");
        }
    }
}

#[test]
fn every_truncation_is_refused_by_both() {
    for (ascii, flags) in [(None, true), (None, false), (Some((" ", "\n")), false), (Some(("  ", "\r\n")), true)] {
        // Binary without a property after the list takes the fast path for faces.
        let l = Layout { flags, ..every_part(ascii) };
        let bytes = file(l, 20, 30, 7);
        let header_end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        // An ASCII file may lose the end of its last line.
        let whole = bytes.len() - if ascii.is_some() { 2 } else { 0 };
        for cut in header_end..bytes.len() {
            if cut < whole {
                assert!(read(&bytes[..cut]).is_err(), "cut at {cut}");
            }
            same(&bytes[..cut], &format!("cut at {cut}"));
        }
    }
}

#[test]
fn ascii_errors_name_the_line_and_the_entry() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n";
    let e = read(text.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("line 12: 'vertex' entry 2 has \"zero\""), "{e}");
    let short = text.replace("zero", "0").replace("3 0 1 2", "3 0 1");
    let e = read(short.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("line 13: 'face' entry 0 has too few numbers"), "{e}");
    let e = read(text.replace("0 1 zero\n3 0 1 2\n", "0 1 0.000000\n").as_bytes()).unwrap_err().to_string();
    assert!(e.contains("the file ends inside 'face' entry 0 of 1"), "{e}");
}

#[test]
fn missing_or_wrong_properties_are_refused_like_the_reference() {
    for ascii in [None, Some((" ", "\n"))] {
        let l = Layout { before: false, colour: None, between: false, flags: false, ..every_part(ascii) };
        let good = file(l, 10, 5, 3);
        for (from, to) in [
            ("property float y\n", "property float w\n"),
            ("vertex_indices", "vertex_indexes"),
            ("element face", "element facet"),
            ("list uchar int", "list uchar float"),
            ("element vertex 10", "element points 10"),
        ] {
            let text = String::from_utf8_lossy(&good).replacen(from, to, 1);
            let bytes: Vec<u8> = if from.len() == to.len() {
                let at = good.windows(from.len()).position(|w| w == from.as_bytes()).unwrap();
                let mut b = good.clone();
                b[at..at + to.len()].copy_from_slice(to.as_bytes());
                b
            } else {
                let at = good.windows(from.len()).position(|w| w == from.as_bytes()).unwrap();
                [&good[..at], to.as_bytes(), &good[at + from.len()..]].concat()
            };
            let _ = text;
            assert!(read(&bytes).is_err(), "{to}");
            same(&bytes, to);
        }
    }
}

/// What the fuzz target asks, on mutated files: where the reference reads
/// the bytes, the in-place readers give the same mesh; they may read
/// what it refuses (ASCII values past their type's range, malformed lines
/// of elements no mesh uses), never refuse what it reads.
#[test]
fn mutated_files_never_refuse_what_the_reference_reads() {
    let mut r = Lcg(99);
    let alphabet = b"0123456789 -+.e\n\r\t3";
    for (n, ascii) in [None, Some((" ", "\n")), Some(("\t", "\r\n"))].into_iter().enumerate() {
        let l = Layout { flags: n == 1, ..every_part(ascii) };
        let good = file(l, 12, 16, n as u64);
        let header_end = good.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        for round in 0..3000 {
            let mut b = good.clone();
            for _ in 0..1 + r.next() % 3 {
                let at = header_end + (r.next() as usize) % (b.len() - header_end);
                let byte = if ascii.is_some() { alphabet[(r.next() as usize) % alphabet.len()] } else { r.next() as u8 };
                match r.next() % 3 {
                    0 => b[at] = byte,
                    1 => b.insert(at, byte),
                    _ => _ = b.remove(at),
                }
            }
            if let Ok(want) = reference::read(&b) {
                let got = read(&b).unwrap_or_else(|e| panic!("layout {n} round {round}: the reference reads it, ours: {e}"));
                assert_eq!(got.mesh, want.mesh, "layout {n} round {round}");
                assert_eq!(got.appearance.vertex_colour, want.appearance.vertex_colour, "layout {n} round {round}");
            }
        }
    }
}
