//! What a PLY payload holds for a mesh, and the layout facts both payload
//! readers (`ply_binary.rs`, `ply_ascii.rs`) read off the header once:
//! where a vertex's coordinates and colour are, which list of a face
//! element holds its vertex indices, and where those lists go.

use glam::DVec3;
use ply_rs_bw::ply::{ElementDef, PropertyType, ScalarType};

use crate::error::ErrorKind;
use crate::mesh_report::fan;

/// What a payload holds for a mesh.
#[derive(Default)]
pub(crate) struct Payload {
    pub positions: Vec<DVec3>,
    /// sRGB per vertex, when the vertices have colour properties.
    pub colours: Vec<[u8; 3]>,
    /// The `face` element's polygons, fanned into triangles.
    pub triangles: Vec<[i64; 3]>,
    /// Whether the file has a `face` element.
    pub faces: bool,
    /// The index lists of `tristrips`, flattened, with each list's length.
    pub strips: Option<(Vec<i64>, Vec<u32>)>,
}

/// Where an element's index lists go.
pub(crate) enum Lists<'a> {
    /// Fanned into triangles (`face`).
    Fanned(&'a mut Vec<[i64; 3]>),
    /// Kept as they are, with their lengths (`tristrips`).
    Flat(&'a mut (Vec<i64>, Vec<u32>)),
}

impl Lists<'_> {
    /// Takes one entry's list.
    #[inline]
    pub fn push(&mut self, list: &[i64]) {
        match self {
            Lists::Fanned(t) => match *list {
                [a, b, c] => t.push([a, b, c]),
                _ => fan(list, t),
            },
            Lists::Flat((items, lens)) => {
                items.extend_from_slice(list);
                lens.push(list.len() as u32);
            }
        }
    }

    /// Room for `entries` more lists, most of them triangles.
    pub fn reserve(&mut self, entries: usize) {
        match self {
            Lists::Fanned(t) => t.reserve(entries),
            Lists::Flat((items, lens)) => {
                items.reserve(entries * 3);
                lens.reserve(entries);
            }
        }
    }
}

/// The position of `el`'s index list (`vertex_indices` or `vertex_index`)
/// among its properties, refused when it is missing or holds no integers
/// (and the element has entries).
pub(crate) fn index_list(el: &ElementDef) -> Result<Option<usize>, ErrorKind> {
    let keep = el.properties.get_index_of("vertex_indices").or_else(|| el.properties.get_index_of("vertex_index"));
    let is_index = keep.is_some_and(|k| match &el.properties[k].data_type {
        PropertyType::List(_, it) => !matches!(it, ScalarType::Float | ScalarType::Double),
        PropertyType::Scalar(_) => false,
    });
    if !is_index && el.count > 0 {
        return Err(ErrorKind::malformed("PLY", format!("{} 0 has no 'vertex_indices' list", el.name)));
    }
    Ok(keep.filter(|_| is_index))
}

/// A scalar property: its position among the element's properties and its type.
pub(crate) type At = (usize, ScalarType);

/// Where a vertex's coordinates and colour channels are.
pub(crate) struct VertexLayout {
    pub xyz: [At; 3],
    pub colour: Option<[At; 3]>,
}

impl VertexLayout {
    /// Reads the layout off the `vertex` element: `x y z` scalars are
    /// required; `red green blue` (or `r g b`, or `diffuse_*`) are the colour.
    pub fn of(el: &ElementDef) -> Result<VertexLayout, ErrorKind> {
        let scalar_at = |name: &str| -> Option<At> {
            let i = el.properties.get_index_of(name)?;
            match &el.properties[i].data_type {
                PropertyType::Scalar(t) => Some((i, t.clone())),
                PropertyType::List(..) => None,
            }
        };
        let coord =
            |name: &str| scalar_at(name).ok_or_else(|| ErrorKind::malformed("PLY", format!("vertex 0 has no numeric '{name}' property")));
        let xyz = [coord("x")?, coord("y")?, coord("z")?];
        let colour = [["red", "green", "blue"], ["r", "g", "b"], ["diffuse_red", "diffuse_green", "diffuse_blue"]]
            .iter()
            .find_map(|n| Some([scalar_at(n[0])?, scalar_at(n[1])?, scalar_at(n[2])?]));
        Ok(VertexLayout { xyz, colour })
    }

    /// Whether the colour channels are floats in [0, 1] (else bytes).
    pub fn float_colour(&self) -> bool {
        self.colour.as_ref().is_some_and(|c| matches!(c[0].1, ScalarType::Float | ScalarType::Double))
    }
}

/// A colour channel as sRGB: bytes as they are, floats in [0, 1] scaled.
pub(crate) fn channel(x: f64, float: bool) -> u8 {
    if float {
        (x.clamp(0.0, 1.0) * 255.0).round() as u8
    } else {
        x.clamp(0.0, 255.0) as u8
    }
}
