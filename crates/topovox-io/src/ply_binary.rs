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

/// What a payload holds for a mesh.
#[derive(Default)]
pub(crate) struct Payload {
    pub positions: Vec<DVec3>,
    /// sRGB per vertex, when the vertices have colour properties.
    pub colours: Vec<[u8; 3]>,
    /// The index lists of `face`, flattened, with each list's length.
    pub faces: Option<(Vec<i64>, Vec<u32>)>,
    /// The index lists of `tristrips`, likewise.
    pub strips: Option<(Vec<i64>, Vec<u32>)>,
}

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
            "face" | "tristrips" => {
                let keep = index_list(el);
                let is_index = keep.is_some_and(|k| match &el.properties[k].data_type {
                    PropertyType::List(_, it) => !matches!(it, ScalarType::Float | ScalarType::Double),
                    PropertyType::Scalar(_) => false,
                });
                if !is_index && el.count > 0 {
                    return Err(ErrorKind::malformed("PLY", format!("{name} 0 has no 'vertex_indices' list")));
                }
                let mut lists = (Vec::new(), Vec::new());
                let end = walk(el, body, at, big, keep, &mut lists)?;
                if name == "face" {
                    out.faces = Some(lists);
                } else {
                    out.strips = Some(lists);
                }
                end
            }
            _ => walk(el, body, at, big, None, &mut (Vec::new(), Vec::new()))?,
        };
    }
    Ok(out)
}

/// The position of the index list among `el`'s properties.
fn index_list(el: &ElementDef) -> Option<usize> {
    el.properties.get_index_of("vertex_indices").or_else(|| el.properties.get_index_of("vertex_index"))
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
    let scalar_at = |name: &str| -> Option<(usize, ScalarType)> {
        let i = el.properties.get_index_of(name)?;
        match &el.properties[i].data_type {
            PropertyType::Scalar(t) => Some((i, t.clone())),
            PropertyType::List(..) => None,
        }
    };
    let mut xyz = Vec::with_capacity(3);
    for (a, name) in ["x", "y", "z"].iter().enumerate() {
        let Some(found) = scalar_at(name) else {
            return Err(ErrorKind::malformed("PLY", format!("vertex 0 has no numeric '{name}' property")));
        };
        debug_assert_eq!(xyz.len(), a);
        xyz.push(found);
    }
    let colour = [["red", "green", "blue"], ["r", "g", "b"], ["diffuse_red", "diffuse_green", "diffuse_blue"]]
        .iter()
        .find_map(|n| Some([scalar_at(n[0])?, scalar_at(n[1])?, scalar_at(n[2])?]));
    let Some(stride) = stride.filter(|&s| s > 0) else {
        return vertices_walked(el, body, at, big, &xyz, colour.as_ref(), out);
    };
    let end = stride.checked_mul(el.count).and_then(|n| n.checked_add(at)).filter(|&e| e <= body.len());
    let Some(end) = end else { return Err(ended(el, (body.len() - at.min(body.len())) / stride)) };
    let off = |(i, _): &(usize, ScalarType)| offsets[*i].expect("every property is a scalar");
    let [ox, oy, oz] = [off(&xyz[0]), off(&xyz[1]), off(&xyz[2])];
    let [tx, ty, tz] = [xyz[0].1.clone(), xyz[1].1.clone(), xyz[2].1.clone()];
    out.positions.reserve(el.count);
    for row in body[at..end].chunks_exact(stride) {
        out.positions.push(DVec3::new(number(&tx, &row[ox..], big), number(&ty, &row[oy..], big), number(&tz, &row[oz..], big)));
    }
    if let Some(c) = &colour {
        let float = matches!(c[0].1, ScalarType::Float | ScalarType::Double);
        let o = [off(&c[0]), off(&c[1]), off(&c[2])];
        out.colours =
            body[at..end].chunks_exact(stride).map(|row| [0, 1, 2].map(|k| channel(number(&c[k].1, &row[o[k]..], big), float))).collect();
    }
    Ok(end)
}

/// A colour channel as sRGB: bytes as they are, floats in [0, 1] scaled.
fn channel(x: f64, float: bool) -> u8 {
    if float {
        (x.clamp(0.0, 1.0) * 255.0).round() as u8
    } else {
        x.clamp(0.0, 255.0) as u8
    }
}

/// Vertices with a list property among their properties, entry by entry.
fn vertices_walked(
    el: &ElementDef,
    body: &[u8],
    at: usize,
    big: bool,
    xyz: &[(usize, ScalarType)],
    colour: Option<&[(usize, ScalarType); 3]>,
    out: &mut Payload,
) -> Result<usize, ErrorKind> {
    let mut at = at;
    let mut values = vec![0.0; el.properties.len()];
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
        if let Some(c) = colour {
            let float = matches!(c[0].1, ScalarType::Float | ScalarType::Double);
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

/// Walks `el`'s entries from `body[at..]`, collecting the list property
/// at `keep` (if any) into `lists` (the indices, and each list's length).
/// Returns where the element ends.
fn walk(
    el: &ElementDef,
    body: &[u8],
    at: usize,
    big: bool,
    keep: Option<usize>,
    lists: &mut (Vec<i64>, Vec<u32>),
) -> Result<usize, ErrorKind> {
    let props: Vec<&PropertyType> = el.properties.values().map(|p| &p.data_type).collect();
    let mut at = at;
    if keep.is_some() {
        // Most faces are triangles: three indices each.
        lists.0.reserve(el.count.min(body.len()) * 3);
        lists.1.reserve(el.count.min(body.len()));
    }
    for entry in 0..el.count {
        for (k, p) in props.iter().enumerate() {
            at = match p {
                PropertyType::Scalar(t) => Some(at + size(t)).filter(|&e| e <= body.len()).ok_or_else(|| ended(el, entry))?,
                PropertyType::List(ct, it) if keep == Some(k) => {
                    let end = skip_list(ct, it, body, at, big).ok_or_else(|| ended(el, entry))?;
                    let items = &body[at + size(ct)..end];
                    lists.0.extend(items.chunks_exact(size(it)).map(|b| integer(it, b, big)));
                    lists.1.push((items.len() / size(it)) as u32);
                    end
                }
                PropertyType::List(ct, it) => skip_list(ct, it, body, at, big).ok_or_else(|| ended(el, entry))?,
            };
        }
    }
    Ok(at)
}
