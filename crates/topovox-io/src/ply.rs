//! PLY, ASCII and binary (both endiannesses): the header through the
//! `ply-rs-bw` crate, payloads in place (`ply_binary.rs`, `ply_ascii.rs`;
//! the crate's payload parser is their [`reference`](mod@reference)).
//!
//! Reads element `vertex` (properties `x`, `y`, `z`, any numeric type),
//! element `face` (list property `vertex_indices` or `vertex_index`;
//! polygons are fan-triangulated) and element `tristrips` (the same list,
//! triangle strips, `-1` starting a new strip; common in older scans).

use std::io::Cursor;

use glam::DVec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, Encoding, Header, Property, PropertyType, ScalarType};

use crate::error::ErrorKind;
use crate::mesh_report::{fan, finish, LoadedMesh};

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}

/// Parses PLY bytes: the header by `ply-rs-bw`, the payload in place
/// (`ply_binary.rs`, `ply_ascii.rs`).
pub fn read(bytes: &[u8]) -> Result<LoadedMesh, ErrorKind> {
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = parser.read_header(&mut reader).map_err(|e| ErrorKind::malformed("PLY", e))?;
    let start = reader.get_ref().position() as usize;
    check_counts(&header, (bytes.len() - start) as u64)?;
    let p = if header.encoding == Encoding::Ascii {
        let header_lines = memchr::memchr_iter(b'\n', &bytes[..start]).count();
        crate::ply_ascii::read(&header, &bytes[start..], header_lines)?
    } else {
        crate::ply_binary::read(&header, &bytes[start..])?
    };
    let mut triangles = p.triangles;
    if let Some((idx, lens)) = &p.strips {
        let mut at = 0;
        for &n in lens {
            for strip in idx[at..at + n as usize].split(|&v| v == -1) {
                unstrip(strip, &mut triangles);
            }
            at += n as usize;
        }
    }
    if !p.faces && p.strips.is_none() {
        return Err(no_faces(&header));
    }
    let mut colours = p.colours;
    if !colours.is_empty() {
        colours.resize(p.positions.len(), [255; 3]);
    }
    let mut loaded = finish(p.positions, triangles, Vec::new())?;
    loaded.appearance.vertex_colour = colours;
    Ok(loaded)
}

fn no_faces(header: &Header) -> ErrorKind {
    let names: Vec<&str> = header.elements.keys().map(String::as_str).collect();
    ErrorKind::malformed("PLY", format!("no 'face' or 'tristrips' element to read triangles from (it has: {})", names.join(", ")))
}

/// The reader by `ply-rs-bw`'s payload parser, for every encoding: the
/// reference the in-place readers are tested against.
pub mod reference {
    use super::*;

    /// Parses PLY bytes with the crate's payload parser.
    pub fn read(bytes: &[u8]) -> Result<LoadedMesh, ErrorKind> {
        let parser = Parser::<DefaultElement>::new();
        let mut reader = Reader::new(Cursor::new(bytes));
        let header = parser.read_header(&mut reader).map_err(|e| ErrorKind::malformed("PLY", e))?;
        let payload_len = bytes.len() as u64 - reader.get_ref().position();
        check_counts(&header, payload_len)?;
        payload(&parser, &mut reader, &header)
    }

    pub(super) fn payload(
        parser: &Parser<DefaultElement>,
        reader: &mut Reader<Cursor<&[u8]>>,
        header: &Header,
    ) -> Result<LoadedMesh, ErrorKind> {
        let payload = parser.read_payload(reader, header).map_err(|e| ErrorKind::malformed("PLY", e))?;
        let verts = payload.get("vertex").ok_or_else(|| ErrorKind::malformed("PLY", "no 'vertex' element"))?;
        let mut positions = Vec::with_capacity(verts.len());
        let mut colours = Vec::new();
        for (n, v) in verts.iter().enumerate() {
            if let Some(c) = vertex_colour(v) {
                colours.resize(n, [255; 3]);
                colours.push(c);
            }
            let mut c = [0.0; 3];
            for (a, name) in ["x", "y", "z"].iter().enumerate() {
                c[a] = v
                    .get(*name)
                    .and_then(scalar)
                    .ok_or_else(|| ErrorKind::malformed("PLY", format!("vertex {n} has no numeric '{name}' property")))?;
            }
            positions.push(DVec3::from(c));
        }
        let mut triangles = Vec::new();
        for idx in index_lists(&payload, "face")? {
            fan(&idx, &mut triangles);
        }
        for idx in index_lists(&payload, "tristrips")? {
            for strip in idx.split(|&v| v == -1) {
                unstrip(strip, &mut triangles);
            }
        }
        if payload.get("face").is_none() && payload.get("tristrips").is_none() {
            return Err(no_faces(header));
        }
        if !colours.is_empty() {
            colours.resize(positions.len(), [255; 3]);
        }
        let mut loaded = finish(positions, triangles, Vec::new())?;
        loaded.appearance.vertex_colour = colours;
        Ok(loaded)
    }
}

/// The `vertex_indices` (or `vertex_index`) lists of every entry of
/// `element` (none when the file has no such element).
fn index_lists(payload: &ply_rs_bw::ply::Payload<DefaultElement>, element: &str) -> Result<Vec<Vec<i64>>, ErrorKind> {
    let Some(entries) = payload.get(element) else { return Ok(Vec::new()) };
    entries
        .iter()
        .enumerate()
        .map(|(n, e)| {
            e.get("vertex_indices")
                .or_else(|| e.get("vertex_index"))
                .and_then(list)
                .ok_or_else(|| ErrorKind::malformed("PLY", format!("{element} {n} has no 'vertex_indices' list")))
        })
        .collect()
}

/// The triangles of one triangle strip, every other one turned so all
/// keep the strip's orientation; the degenerate ones that join strips
/// (a vertex repeated) are left out.
fn unstrip(strip: &[i64], out: &mut Vec<[i64; 3]>) {
    for (n, w) in strip.windows(3).enumerate() {
        let t = if n % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] };
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            out.push(t);
        }
    }
}

/// Refuses a header whose element counts cannot fit in the bytes after it:
/// each entry takes at least one byte (an ASCII line, or the sizes of its
/// binary scalars and list counts). Without this a 100-byte file claiming
/// 400 million property-less vertices keeps the parser busy for minutes.
fn check_counts(header: &Header, payload_len: u64) -> Result<(), ErrorKind> {
    let mut need: u64 = 0;
    for (name, el) in header.elements.iter() {
        let per_entry: u64 = el
            .properties
            .values()
            .map(|p| match (&header.encoding, &p.data_type) {
                (Encoding::Ascii, _) => 2,
                (_, PropertyType::Scalar(t)) | (_, PropertyType::List(t, _)) => scalar_size(t),
            })
            .sum::<u64>()
            .max(1);
        need = need.saturating_add((el.count as u64).saturating_mul(per_entry));
        // One byte of slack: the last ASCII line may lack its newline.
        if need > payload_len + 1 {
            return Err(ErrorKind::malformed(
                "PLY",
                format!("the header claims {} '{name}' entries, more than the {payload_len} bytes after it can hold", el.count),
            ));
        }
    }
    Ok(())
}

fn scalar_size(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// A vertex's `red green blue` (or `r g b`, or `diffuse_red` …): bytes, or
/// floats in [0, 1]; sRGB.
fn vertex_colour(v: &DefaultElement) -> Option<[u8; 3]> {
    for names in [["red", "green", "blue"], ["r", "g", "b"], ["diffuse_red", "diffuse_green", "diffuse_blue"]] {
        let (Some(r), Some(g), Some(b)) = (v.get(names[0]), v.get(names[1]), v.get(names[2])) else { continue };
        let float = matches!(r, Property::Float(_) | Property::Double(_));
        let c = [r, g, b].map(|p| scalar(p).unwrap_or(0.0));
        return Some(c.map(|x| if float { (x.clamp(0.0, 1.0) * 255.0).round() as u8 } else { x.clamp(0.0, 255.0) as u8 }));
    }
    None
}
