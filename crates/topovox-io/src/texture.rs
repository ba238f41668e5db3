//! Texture images for coloured voxelization, decoded by the `image` crate
//! (PNG and JPEG) into sRGB RGBA bytes.

use std::path::PathBuf;

use topovox::attributes::{Texture, Wrap};

/// Largest texture accepted, in texels (a 16k × 16k image).
const MAX_TEXELS: u64 = 1 << 28;

/// Decodes image bytes; `name` is used in messages.
pub fn decode(bytes: &[u8], name: &str, wrap: [Wrap; 2]) -> Result<Texture, String> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(|e| format!("texture {name}: {e}"))?;
    let (w, h) = reader.into_dimensions().map_err(|e| format!("texture {name} could not be decoded ({e})"))?;
    if w == 0 || h == 0 || w as u64 * h as u64 > MAX_TEXELS {
        return Err(format!("texture {name} is {w}x{h} texels (at most {MAX_TEXELS} accepted)"));
    }
    let img = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("texture {name}: {e}"))?
        .decode()
        .map_err(|e| format!("texture {name} could not be decoded ({e})"))?
        .to_rgba8();
    Ok(Texture { name: name.to_string(), width: img.width(), height: img.height(), rgba: img.into_raw(), wrap })
}

/// An MTL texture statement (`map_Kd [options] file`): the file (as
/// written, relative to the model's folder unless absolute) and the wrap
/// mode (`-clamp on` clamps; the default repeats). Other options are skipped.
pub fn parse_map_statement(statement: &str) -> (PathBuf, [Wrap; 2]) {
    let words: Vec<&str> = statement.split_whitespace().collect();
    let mut wrap = Wrap::Repeat;
    let mut at = 0;
    while at < words.len() && words[at].starts_with('-') && words.len() - at > 1 {
        let opt = words[at];
        at += 1;
        if opt == "-clamp" {
            if words[at] == "on" {
                wrap = Wrap::ClampToEdge;
            }
            at += 1;
            continue;
        }
        // Skip the option's arguments: numbers, on/off, or one word (-imfchan r, -type sphere).
        let mut taken = 0;
        while at < words.len() - 1
            && (words[at].parse::<f64>().is_ok() || matches!(words[at], "on" | "off") || (taken == 0 && !words[at].contains('.')))
        {
            at += 1;
            taken += 1;
        }
    }
    (PathBuf::from(words[at.min(words.len().saturating_sub(1))..].join(" ")), [wrap; 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_statements() {
        assert_eq!(parse_map_statement("tex.png"), (PathBuf::from("tex.png"), [Wrap::Repeat; 2]));
        assert_eq!(parse_map_statement("-clamp on a b.png"), (PathBuf::from("a b.png"), [Wrap::ClampToEdge; 2]));
        assert_eq!(parse_map_statement("-s 1 1 1 -o 0 0 t.jpg"), (PathBuf::from("t.jpg"), [Wrap::Repeat; 2]));
        assert_eq!(parse_map_statement("-bm 0.5 -imfchan r x.png").0, PathBuf::from("x.png"));
    }
}
