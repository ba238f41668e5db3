//! Fuzzes texture decoding (PNG and JPEG named by OBJ `map_Kd` and glTF
//! images): any bytes give a texture of consistent size or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use voxkit::attributes::Wrap;

fuzz_target!(
    init: {
        // Third-party parsers that panic on malformed input run inside
        // voxkit-io's fence, which turns the panic into an error (as the CLI
        // does); only panics outside it are crashes.
        let abort = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !voxkit_io::panic_is_fenced() {
                abort(info)
            }
        }));
    },
    |data: &[u8]| {
    if let Ok(t) = voxkit_io::texture::decode(data, "fuzz", [Wrap::Repeat; 2]) {
        assert_eq!(t.rgba.len(), t.width as usize * t.height as usize * 4);
    }
    }
);
