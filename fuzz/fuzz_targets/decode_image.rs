//! Fuzzes the image-loading path used for `--background` (and every user image): any bytes
//! must give a pixmap or an error message, never a panic, a hang or a huge allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tidepool::{PoolScene, PoolSettings, Scene};

fuzz_target!(|data: &[u8]| {
    if let Ok(floor) = tidepool::encode::decode_image(data) {
        // A decoded image must be usable: a small pool on it, as the renderer fits it.
        if let Some(mut pool) = PoolScene::new(7, 5, PoolSettings { floor, ..PoolSettings::default() }) {
            let _ = pool.snapshot();
        }
    }
});
