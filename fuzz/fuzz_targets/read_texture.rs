//! Fuzzes texture decoding (PNG and JPEG named by OBJ `map_Kd` and glTF
//! images): any bytes give a texture of consistent size or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox::attributes::Wrap;

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    if let Ok(t) = topovox_io::texture::decode(data, "fuzz", [Wrap::Repeat; 2]) {
        assert_eq!(t.rgba.len(), t.width as usize * t.height as usize * 4);
    }
    }
);
