//! Writing 2D pixel sets (`topovox raster`): PNG pictures and `.npy` arrays.
//!
//! - `.png`: set pixels black on white, pixel `(i, j)` at column `i`, row
//!   `j` from the top (SVG's orientation: no flip).
//! - `.npy`: `uint8`, shape `(W, H)`, C order, element `[i, j]` = pixel `(i, j)`.

use std::io::Write;
use std::path::Path;

use topovox::raster::Pixels;

use crate::atomic::write_atomically;
use crate::error::{ErrorKind, IoError};

/// Writes `px` to `path` as PNG or `.npy`, by the extension.
pub fn write_pixels(path: &Path, px: &Pixels) -> Result<(), IoError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    let [w, h] = px.dims();
    match ext.as_str() {
        "png" => {
            let mut rgb = vec![255u8; w as usize * h as usize * 3];
            for j in 0..h {
                for i in 0..w {
                    if px.get(i as i64, j as i64) {
                        let at = (j as usize * w as usize + i as usize) * 3;
                        rgb[at..at + 3].fill(0);
                    }
                }
            }
            crate::png::write_png(path, w, h, &rgb)
        }
        "npy" => write_atomically(path, |out| write_npy(out, px)),
        other => Err(IoError::new(path, ErrorKind::UnknownFormat { ext: other.to_string(), expected: "png, npy" })),
    }
}

fn write_npy(w: &mut dyn Write, px: &Pixels) -> std::io::Result<()> {
    let [nx, ny] = px.dims();
    let mut header = format!("{{'descr': '|u1', 'fortran_order': False, 'shape': ({nx}, {ny}), }}");
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat(total.div_ceil(64) * 64 - total));
    header.push('\n');
    w.write_all(b"\x93NUMPY\x01\x00")?;
    w.write_all(&(header.len() as u16).to_le_bytes())?;
    w.write_all(header.as_bytes())?;
    let mut row = vec![0u8; ny as usize];
    for i in 0..nx {
        for (j, b) in row.iter_mut().enumerate() {
            *b = px.get(i as i64, j as i64) as u8;
        }
        w.write_all(&row)?;
    }
    Ok(())
}
