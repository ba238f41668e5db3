//! PNG pictures (the `image` crate's encoder), written atomically.

use std::path::Path;

use image::ImageEncoder;

use crate::atomic::write_atomically;
use crate::error::IoError;

/// Writes an 8-bit RGB image (`width · height · 3` bytes, rows top to
/// bottom) as a PNG file.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), IoError> {
    encode(path, width, height, rgb, image::ExtendedColorType::Rgb8)
}

/// Writes an 8-bit RGBA image (`width · height · 4` bytes) as a PNG file.
pub fn write_png_rgba(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<(), IoError> {
    encode(path, width, height, rgba, image::ExtendedColorType::Rgba8)
}

fn encode(path: &Path, width: u32, height: u32, bytes: &[u8], colour: image::ExtendedColorType) -> Result<(), IoError> {
    write_atomically(path, |w| {
        image::codecs::png::PngEncoder::new(w).write_image(bytes, width, height, colour).map_err(std::io::Error::other)
    })
}
