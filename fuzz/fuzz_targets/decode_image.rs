//! Fuzzes the image-loading path used for `--background` (and every user image): any bytes
//! must give a pixmap or an error message, never a panic, a hang or a huge allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(pixmap) = tidepool::render::background::decode(data) {
        // A decoded image must be usable: fit it to a small pool as the renderer does.
        let _ = tidepool::render::background::cover(&pixmap, 7, 5);
    }
});
