//! Binary PLY payloads (both endiannesses) read in place.
//!
//! Hand-written because the one maintained crate, `ply-rs-bw` (which still
//! parses every header here), builds a map of named properties for every
//! vertex and face: 8–14 ms for a 5 k-face file and 0.8 s for 269 k faces,
//! 20–70× Open3D (issue 69). Here each element's layout is read off the
//! header once; a vertex's coordinates and colour are read at fixed
//! offsets when it has no list property (every file seen), and faces walk
//! their list counts. Every read is bounds-checked: a file that ends early,
//! or whose list counts run past it, is an error naming the element and
//! the entry. [`crate::ply::reference`] (the crate's parser) is the
//! reference the tests compare it with, value for value.

use glam::DVec3;
use ply_rs_bw::ply::{ElementDef, Encoding, Header, PropertyType, ScalarType};

use crate::error::ErrorKind;
use crate::ply_payload::{channel, index_list, At, Lists, Payload, VertexLayout};

/// Byte size of a scalar.
pub(crate) fn size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// A scalar of type `t` at the start of `b` (at least its size), as f64.
#[inline]
fn number(t: &ScalarType, b: &[u8], big: bool) -> f64 {
    macro_rules! get {
        ($ty:ty, $n:expr) => {{
            let a: [u8; $n] = b[..$n].try_into().expect("sized");
            (if big { <$ty>::from_be_bytes(a) } else { <$ty>::from_le_bytes(a) }) as f64
        }};
    }
    match t {
        ScalarType::Char => b[0] as i8 as f64,
        ScalarType::UChar => b[0] as f64,
        ScalarType::Short => get!(i16, 2),
        ScalarType::UShort => get!(u16, 2),
        ScalarType::Int => get!(i32, 4),
        ScalarType::UInt => get!(u32, 4),
        ScalarType::Float => get!(f32, 4),
        ScalarType::Double => get!(f64, 8),
    }
}

/// A scalar of an integer type (or a float, truncated) as i64: list
/// counts and vertex indices.
#[inline]
fn integer(t: &ScalarType, b: &[u8], big: bool) -> i64 {
    macro_rules! get {
        ($ty:ty, $n:expr) => {{
            let a: [u8; $n] = b[..$n].try_into().expect("sized");
            (if big { <$ty>::from_be_bytes(a) } else { <$ty>::from_le_bytes(a) }) as i64
        }};
    }
    match t {
        ScalarType::Char => b[0] as i8 as i64,
        ScalarType::UChar => b[0] as i64,
        ScalarType::Short => get!(i16, 2),
        ScalarType::UShort => get!(u16, 2),
        ScalarType::Int => get!(i32, 4),
        ScalarType::UInt => get!(u32, 4),
        // Float indices are not PLY, but the reference reads none either.
        ScalarType::Float | ScalarType::Double => i64::MIN,
    }
}

/// Reads the payload `body` (the bytes after `end_header`) of a binary file.
pub(crate) fn read(header: &Header, body: &[u8]) -> Result<Payload, ErrorKind> {
    let big = header.encoding == Encoding::BinaryBigEndian;
    let mut out = Payload::default();
    if !header.elements.contains_key("vertex") {
        return Err(ErrorKind::malformed("PLY", "no 'vertex' element"));
    }
    let mut at = 0usize;
    for (name, el) in &header.elements {
        at = match name.as_str() {
            "vertex" => vertices(el, body, at, big, &mut out)?,
            "face" => {
                out.faces = true;
                match (index_list(el)?, el.properties.len()) {
                    (Some(0), 1) => faces_only(el, body, at, big, &mut out.triangles)?,
                    (keep, _) => walk(el, body, at, big, keep.map(|k| (k, Lists::Fanned(&mut out.triangles))))?,
                }
            }
            "tristrips" => {
                let keep = index_list(el)?;
                let strips = out.strips.insert((Vec::new(), Vec::new()));
                walk(el, body, at, big, keep.map(|k| (k, Lists::Flat(strips))))?
            }
            _ => walk(el, body, at, big, None)?,
        };
    }
    Ok(out)
}

fn ended(el: &ElementDef, entry: usize) -> ErrorKind {
    ErrorKind::malformed("PLY", format!("the file ends inside '{}' entry {entry} of {}", el.name, el.count))
}

/// The vertices of `el` from `body[at..]`: fixed offsets when every
/// property is a scalar, else [`walk`]ed. Returns where the element ends.
fn vertices(el: &ElementDef, body: &[u8], at: usize, big: bool, out: &mut Payload) -> Result<usize, ErrorKind> {
    let mut offsets = Vec::with_capacity(el.properties.len());
    let mut stride = Some(0usize);
    for p in el.properties.values() {
        offsets.push(stride);
        stride = match (&p.data_type, stride) {
            (PropertyType::Scalar(t), Some(s)) => Some(s + size(t)),
            _ => None,
        };
    }
    let layout = VertexLayout::of(el)?;
    let Some(stride) = stride.filter(|&s| s > 0) else {
        return vertices_walked(el, body, at, big, &layout, out);
    };
    let end = stride.checked_mul(el.count).and_then(|n| n.checked_add(at)).filter(|&e| e <= body.len());
    let Some(end) = end else { return Err(ended(el, (body.len() - at.min(body.len())) / stride)) };
    let off = |(i, _): &At| offsets[*i].expect("every property is a scalar");
    let xyz = &layout.xyz;
    let [ox, oy, oz] = [off(&xyz[0]), off(&xyz[1]), off(&xyz[2])];
    let [tx, ty, tz] = [xyz[0].1.clone(), xyz[1].1.clone(), xyz[2].1.clone()];
    let rows = body[at..end].chunks_exact(stride);
    out.positions =
        rows.map(|row| DVec3::new(number(&tx, &row[ox..], big), number(&ty, &row[oy..], big), number(&tz, &row[oz..], big))).collect();
    if let Some(c) = &layout.colour {
        let float = layout.float_colour();
        let o = [off(&c[0]), off(&c[1]), off(&c[2])];
        out.colours =
            body[at..end].chunks_exact(stride).map(|row| [0, 1, 2].map(|k| channel(number(&c[k].1, &row[o[k]..], big), float))).collect();
    }
    Ok(end)
}

/// Vertices with a list property among their properties, entry by entry.
fn vertices_walked(
    el: &ElementDef,
    body: &[u8],
    at: usize,
    big: bool,
    layout: &VertexLayout,
    out: &mut Payload,
) -> Result<usize, ErrorKind> {
    let mut at = at;
    let mut values = vec![0.0; el.properties.len()];
    let (xyz, float) = (&layout.xyz, layout.float_colour());
    for entry in 0..el.count {
        for (k, p) in el.properties.values().enumerate() {
            at = match &p.data_type {
                PropertyType::Scalar(t) => {
                    let b = body.get(at..at + size(t)).ok_or_else(|| ended(el, entry))?;
                    values[k] = number(t, b, big);
                    at + size(t)
                }
                PropertyType::List(ct, it) => skip_list(ct, it, body, at, big).ok_or_else(|| ended(el, entry))?,
            };
        }
        out.positions.push(DVec3::new(values[xyz[0].0], values[xyz[1].0], values[xyz[2].0]));
        if let Some(c) = &layout.colour {
            out.colours.push([0, 1, 2].map(|k| channel(values[c[k].0], float)));
        }
    }
    Ok(at)
}

/// Where a list starting at `body[at]` ends (None past the file).
fn skip_list(ct: &ScalarType, it: &ScalarType, body: &[u8], at: usize, big: bool) -> Option<usize> {
    let n = integer(ct, body.get(at..at + size(ct))?, big);
    let n = usize::try_from(n).ok()?;
    let end = n.checked_mul(size(it))?.checked_add(at + size(ct))?;
    (end <= body.len()).then_some(end)
}

/// Walks `el`'s entries from `body[at..]`, handing the list property at
/// `keep.0` (if any) of each to `keep.1`. Returns where the element ends.
fn walk(el: &ElementDef, body: &[u8], at: usize, big: bool, keep: Option<(usize, Lists<'_>)>) -> Result<usize, ErrorKind> {
    let props: Vec<&PropertyType> = el.properties.values().map(|p| &p.data_type).collect();
    let (keep, mut lists) = keep.unzip();
    if let Some(l) = &mut lists {
        l.reserve(el.count.min(body.len()));
    }
    let mut at = at;
    let mut list = Vec::new();
    for entry in 0..el.count {
        for (k, p) in props.iter().enumerate() {
            at = match p {
                PropertyType::Scalar(t) => Some(at + size(t)).filter(|&e| e <= body.len()).ok_or_else(|| ended(el, entry))?,
                PropertyType::List(ct, it) => {
                    let end = skip_list(ct, it, body, at, big).ok_or_else(|| ended(el, entry))?;
                    if let (Some(l), true) = (&mut lists, keep == Some(k)) {
                        list.clear();
                        list.extend(body[at + size(ct)..end].chunks_exact(size(it)).map(|b| integer(it, b, big)));
                        l.push(&list);
                    }
                    end
                }
            };
        }
    }
    Ok(at)
}

/// A `face` element whose only property is its index list (what most
/// writers make): the walk without the per-property loop, with the
/// index type's decoding chosen once for the common little-endian types.
fn faces_only(el: &ElementDef, body: &[u8], at: usize, big: bool, triangles: &mut Vec<[i64; 3]>) -> Result<usize, ErrorKind> {
    let PropertyType::List(ct, it) = &el.properties[0].data_type else { unreachable!("an index list") };
    match (ct, it, big) {
        (ScalarType::UChar, ScalarType::Int, false) => {
            faces_with(el, body, at, |b| b[0] as usize, 1, |b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64, 4, triangles)
        }
        (ScalarType::UChar, ScalarType::UInt, false) => {
            faces_with(el, body, at, |b| b[0] as usize, 1, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64, 4, triangles)
        }
        _ => {
            let count = |b: &[u8]| usize::try_from(integer(ct, b, big)).unwrap_or(usize::MAX);
            faces_with(el, body, at, count, size(ct), |b| integer(it, b, big), size(it), triangles)
        }
    }
}

/// [`faces_only`] with the count and index decoders given (and their sizes).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn faces_with(
    el: &ElementDef,
    body: &[u8],
    mut at: usize,
    count: impl Fn(&[u8]) -> usize,
    count_size: usize,
    index: impl Fn(&[u8]) -> i64,
    index_size: usize,
    triangles: &mut Vec<[i64; 3]>,
) -> Result<usize, ErrorKind> {
    triangles.reserve(el.count.min(body.len()));
    let mut list = Vec::new();
    for entry in 0..el.count {
        let n = body.get(at..at + count_size).map(&count).ok_or_else(|| ended(el, entry))?;
        let items =
            n.checked_mul(index_size).and_then(|len| body.get(at + count_size..at + count_size + len)).ok_or_else(|| ended(el, entry))?;
        if n == 3 {
            triangles.push([index(items), index(&items[index_size..]), index(&items[2 * index_size..])]);
        } else {
            list.clear();
            list.extend(items.chunks_exact(index_size).map(&index));
            crate::mesh_report::fan(&list, triangles);
        }
        at += count_size + items.len();
    }
    Ok(at)
}
