//! What reading a mesh file holds at its peak, known before it is parsed,
//! so a file that cannot fit in the memory a read may take (`--max-memory`,
//! else nine tenths of the available memory) is refused in one line
//! instead of running the machine out of memory half-way (#65).
//!
//! The counts come from what the file declares where its format declares
//! them (a binary STL's triangle count, a binary PLY's element counts),
//! else from its lines (OBJ, OFF, ASCII PLY and STL: each line holds at
//! most one vertex or one face); glTF is counted from its accessors by its
//! reader ([`crate::gltf`]). Each count is multiplied by what its reader
//! was measured to hold per element at the peak, on meshes and on soups
//! (every vertex its own: the most a triangle can cost), with the file's
//! own bytes added. A polygon of `k` corners on one line of a text file
//! becomes `k − 2` triangles and is counted as one line: such files can
//! take more than the estimate (about 40 bytes per extra triangle).

/// How a format's reading is counted (the reader's module maps its
/// formats here, so this module needs none of them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Counted {
    /// STL: a binary file's declared triangles, or an ASCII file's lines.
    Stl,
    /// PLY: a binary file's declared elements, or an ASCII file's lines.
    Ply,
    /// OBJ, OFF, polylines: lines.
    Lines,
    /// glTF: counted by its reader from the accessors.
    Gltf,
}

/// Bytes held per element at the peak of each reader beyond the file's
/// bytes, measured on 10⁶-triangle grids and soups (2026-12-02, `topovox
/// info` peak resident size) and rounded up.
mod per {
    /// A binary STL triangle with its three vertices (a soup's: 207).
    pub const STL_TRIANGLE: u64 = 224;
    /// A line of an ASCII STL (`vertex`, `facet`, …; a soup's: 29).
    pub const STL_TEXT_LINE: u64 = 32;
    /// A line of an OBJ or OFF file (measured 27–37).
    pub const TEXT_LINE: u64 = 44;
    /// A line of an ASCII PLY file (the `ply-rs` parser keeps each element
    /// as a map: measured 460–473).
    pub const PLY_TEXT_LINE: u64 = 512;
    /// A binary PLY vertex (measured 23).
    pub const PLY_VERTEX: u64 = 28;
    /// A binary PLY face (measured 70).
    pub const PLY_FACE: u64 = 80;
}

/// About the bytes reading `bytes` as `format` holds at its peak, the
/// file's own bytes included (glTF: the file's bytes only; see the module
/// doc).
pub(crate) fn peak(format: Counted, bytes: &[u8]) -> u64 {
    let file = bytes.len() as u64;
    let lines = || memchr::memchr_iter(b'\n', bytes).count() as u64 + 1;
    let extra = match format {
        Counted::Stl => match binary_stl_triangles(bytes) {
            Some(t) => t.saturating_mul(per::STL_TRIANGLE),
            None => lines().saturating_mul(per::STL_TEXT_LINE),
        },
        Counted::Ply => match ply_counts(bytes) {
            Some((v, f)) => v.min(file).saturating_mul(per::PLY_VERTEX).saturating_add(f.min(file).saturating_mul(per::PLY_FACE)),
            None => lines().saturating_mul(per::PLY_TEXT_LINE),
        },
        Counted::Lines => lines().saturating_mul(per::TEXT_LINE),
        Counted::Gltf => 0,
    };
    file.saturating_add(extra)
}

/// Fails when reading `bytes` as `format` would hold more than `limit`.
pub(crate) fn check(format: Counted, bytes: &[u8], limit: impl FnOnce() -> u64) -> Result<(), crate::ErrorKind> {
    refuse_past(peak(format, bytes), limit)
}

/// Fails when a read needs more than `limit` bytes; needs below
/// [`crate::UNCHECKED_BYTES`] are not checked (nor `limit` computed).
pub(crate) fn refuse_past(need: u64, limit: impl FnOnce() -> u64) -> Result<(), crate::ErrorKind> {
    if need < crate::UNCHECKED_BYTES {
        return Ok(());
    }
    let available = limit();
    if need > available {
        return Err(crate::ErrorKind::TooLargeToRead { need: crate::bytes(need), available: crate::bytes(available) });
    }
    Ok(())
}

/// A binary STL's declared triangle count (None for ASCII).
fn binary_stl_triangles(bytes: &[u8]) -> Option<u64> {
    if crate::stl::looks_ascii(bytes) || bytes.len() < 84 {
        return None;
    }
    // A header claiming more than the file holds is the reader's error
    // (truncated), not a memory refusal.
    let declared = u64::from(u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]));
    Some(declared.min((bytes.len() as u64 - 84) / 50))
}

/// A binary PLY's declared vertex and face counts (None for ASCII or an
/// unreadable header, which the reader reports).
fn ply_counts(bytes: &[u8]) -> Option<(u64, u64)> {
    let head = &bytes[..bytes.len().min(1 << 16)];
    let end = memchr::memmem::find(head, b"end_header")?;
    let text = std::str::from_utf8(&head[..end]).ok()?;
    let (mut binary, mut vertices, mut faces) = (false, 0u64, 0u64);
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", f, ..] => binary = f.starts_with("binary"),
            ["element", "vertex", n] => vertices = n.parse().ok()?,
            ["element", _, n] => faces = faces.saturating_add(n.parse().ok()?),
            _ => {}
        }
    }
    binary.then_some((vertices, faces))
}
