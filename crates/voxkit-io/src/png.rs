//! PNG pictures (the `image` crate's encoder), written atomically.

use std::path::Path;

use image::ImageEncoder;

use crate::atomic::write_atomically;
use crate::error::IoError;

/// Writes an 8-bit RGB image (`width · height · 3` bytes, rows top to
/// bottom) as a PNG file.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), IoError> {
    write_atomically(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
            .map_err(std::io::Error::other)
    })
}
