//! Pictures for the graphics tests: a frame the pool scene rendered (its golden image) and
//! incompressible noise.

/// The pool's golden picture (640x360) as (width, height, RGB): decoded once, then copied (the
/// stream tests take it for every frame; decoding it each time was half of the longest unit
/// test's CPU).
pub fn golden_pool() -> (u32, u32, Vec<u8>) {
    static DECODED: std::sync::OnceLock<(u32, u32, Vec<u8>)> = std::sync::OnceLock::new();
    DECODED
        .get_or_init(|| {
            let png = include_bytes!("../../../tests/golden/pool_default.png");
            let image = image::load_from_memory(png).expect("the golden image decodes").to_rgb8();
            let (w, h) = image.dimensions();
            (w, h, image.into_raw())
        })
        .clone()
}

/// `w x h` pixels of deterministic noise (an xorshift generator seeded with `seed`).
pub fn noise(w: u32, h: u32, seed: u64) -> Vec<u8> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..w as usize * h as usize * 3)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 32) as u8
        })
        .collect()
}
