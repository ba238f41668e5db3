//! Colour spaces: sRGB transfer (IEC 61966-2-1) and Oklab (B. Ottosson,
//! "A perceptual color space for image processing", 2020).
//!
//! Averages are taken in linear light (averaging sRGB bytes darkens and
//! muddies edges); palette distances are measured in Oklab, where equal
//! distances look roughly equally different.

use std::sync::OnceLock;

/// sRGB byte → linear light in [0, 1].
pub fn to_linear(c: u8) -> f64 {
    static LUT: OnceLock<[f64; 256]> = OnceLock::new();
    LUT.get_or_init(|| {
        std::array::from_fn(|i| {
            let s = i as f64 / 255.0;
            if s <= 0.04045 {
                s / 12.92
            } else {
                ((s + 0.055) / 1.055).powf(2.4)
            }
        })
    })[c as usize]
}

/// Linear light → the nearest sRGB byte (clamped to [0, 1] first).
/// `from_linear(to_linear(c)) == c` for every byte `c` (tested).
pub fn from_linear(l: f64) -> u8 {
    let l = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    let s = if l <= 0.0031308 { l * 12.92 } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}

/// An sRGB colour as linear RGB.
pub fn rgb_to_linear(c: [u8; 3]) -> [f64; 3] {
    c.map(to_linear)
}

/// Linear RGB as an sRGB colour.
pub fn linear_to_rgb(l: [f64; 3]) -> [u8; 3] {
    l.map(from_linear)
}

/// An sRGB colour in Oklab `(L, a, b)`.
pub fn oklab(c: [u8; 3]) -> [f32; 3] {
    let [r, g, b] = rgb_to_linear(c);
    let l = 0.4122214708 * r + 0.5363325363 * g + 0.0514459929 * b;
    let m = 0.2119034982 * r + 0.6806995451 * g + 0.1073969566 * b;
    let s = 0.0883024619 * r + 0.2817188376 * g + 0.6299787005 * b;
    let (l, m, s) = (l.cbrt(), m.cbrt(), s.cbrt());
    [
        (0.2104542553 * l + 0.7936177850 * m - 0.0040720468 * s) as f32,
        (1.9779984951 * l - 2.4285922050 * m + 0.4505937099 * s) as f32,
        (0.0259040371 * l + 0.7827717662 * m - 0.8086757660 * s) as f32,
    ]
}

/// Squared Oklab distance.
pub fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|i| (a[i] - b[i]) * (a[i] - b[i])).sum()
}

/// Packs an sRGB colour as `0xRRGGBB`.
pub fn pack(c: [u8; 3]) -> u32 {
    (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32
}

/// Unpacks `0xRRGGBB`.
pub fn unpack(c: u32) -> [u8; 3] {
    [(c >> 16) as u8, (c >> 8) as u8, c as u8]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_every_byte() {
        for c in 0..=255u8 {
            assert_eq!(from_linear(to_linear(c)), c);
        }
    }

    #[test]
    fn oklab_of_white_and_black() {
        let w = oklab([255, 255, 255]);
        assert!((w[0] - 1.0).abs() < 1e-3 && w[1].abs() < 1e-3 && w[2].abs() < 1e-3);
        assert!(oklab([0, 0, 0])[0].abs() < 1e-6);
        assert_eq!(unpack(pack([1, 2, 3])), [1, 2, 3]);
    }
}
