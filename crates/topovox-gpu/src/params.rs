//! The per-pass uniform parameters every voxelization shader reads
//! (`Params` in `shaders/common.wgsl`), as one typed `#[repr(C)]` struct
//! whose layout is checked against its WGSL twin by a test (names, offsets
//! and size under WGSL's uniform layout rules).

use bytemuck::{Pod, Zeroable};

/// `Params::mode`'s flag: the rasterizer draws each triangle's pixel-aligned
/// bounding rectangle (two triangles) instead of the triangle, and the
/// fragment shader culls by the exact tests (no hardware conservative
/// rasterization).
pub(crate) const QUADS: u32 = 16;

/// One pass's parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub(crate) struct Params {
    /// Grid dims.
    pub dims: [u32; 3],
    /// The slab's first layer.
    pub k0: u32,
    /// Layers in the slab.
    pub nk: u32,
    /// 32-bit words per row of bits.
    pub words_per_row: u32,
    /// Triangles (or items) of the pass.
    pub count: u32,
    /// The voxelization mode in bits 0-1 (0 cover, 1 sep26, 2 sep6), and [`QUADS`].
    pub mode: u32,
    /// The rasterizer's viewport side.
    pub side: u32,
    /// Pads the struct to WGSL's 16-byte uniform size.
    pub pad: [u32; 3],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(name, offset, size)` of each field of `struct Params` in WGSL,
    /// laid out by WGSL's rules for the types it uses (`u32`: align 4,
    /// size 4; `vec3<u32>`: align 16, size 12), and the struct's size
    /// (rounded up to its alignment, and to 16 for a uniform).
    fn wgsl_layout(src: &str) -> (Vec<(String, usize, usize)>, usize) {
        let body = src.split("struct Params {").nth(1).and_then(|s| s.split("};").next()).expect("struct Params in common.wgsl");
        let (mut fields, mut at, mut align_max) = (Vec::new(), 0usize, 4usize);
        for line in body.lines().map(|l| l.split("//").next().unwrap_or("").trim()).filter(|l| !l.is_empty()) {
            let (name, ty) = line.trim_end_matches(',').split_once(':').expect("name: type");
            let (align, size) = match ty.trim() {
                "u32" => (4, 4),
                "vec3<u32>" => (16, 12),
                t => panic!("a type the layout test does not know: {t}"),
            };
            at = at.next_multiple_of(align);
            fields.push((name.trim().to_string(), at, size));
            at += size;
            align_max = align_max.max(align);
        }
        (fields, at.next_multiple_of(align_max).next_multiple_of(16))
    }

    #[test]
    fn the_rust_struct_matches_its_wgsl_twin() {
        let (fields, size) = wgsl_layout(include_str!("shaders/common.wgsl"));
        assert_eq!(size, std::mem::size_of::<Params>());
        let rust = [
            ("dims", std::mem::offset_of!(Params, dims), 12),
            ("k0", std::mem::offset_of!(Params, k0), 4),
            ("nk", std::mem::offset_of!(Params, nk), 4),
            ("words_per_row", std::mem::offset_of!(Params, words_per_row), 4),
            ("count", std::mem::offset_of!(Params, count), 4),
            ("mode", std::mem::offset_of!(Params, mode), 4),
            ("side", std::mem::offset_of!(Params, side), 4),
        ];
        for (name, offset, bytes) in rust {
            let f = fields.iter().find(|f| f.0 == name).unwrap_or_else(|| panic!("{name} is not in the WGSL struct"));
            assert_eq!((f.1, f.2), (offset, bytes), "{name}");
        }
        // Every WGSL field but the pads has its Rust twin.
        for f in fields.iter().filter(|f| !f.0.starts_with("pad")) {
            assert!(rust.iter().any(|r| r.0 == f.0), "{} has no Rust twin", f.0);
        }
    }
}
