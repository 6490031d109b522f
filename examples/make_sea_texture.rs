//! Generates `assets/sea_texture.png`, the built-in sea texture the ocean stretches over its
//! mesh (the paper uses a photograph of the sea; tidepool ships a synthetic one it can
//! license): deep blue-green water with broad patches of colour and a net of faint ridges, like
//! light scattered under a wind-roughened surface. It tiles seamlessly, because every pattern
//! in it is a sum of cosines with a whole number of periods across the tile.
//!
//! Run once with `cargo run --release --example make_sea_texture`; the PNG is committed.

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const SIZE: usize = 512;

/// A tileable noise: random cosines with integer wave vectors whose length lies in `lo..hi`
/// (periods per tile), amplitude falling as 1/|k|, normalised to unit standard deviation.
fn tileable(rng: &mut ChaCha8Rng, lo: f64, hi: f64, count: usize) -> Vec<f64> {
    let mut waves = Vec::new();
    while waves.len() < count {
        let (m, n) = (rng.random_range(-(hi as i32)..=hi as i32), rng.random_range(-(hi as i32)..=hi as i32));
        let k = f64::from(m * m + n * n).sqrt();
        if k >= lo && k < hi {
            waves.push((f64::from(m), f64::from(n), 1.0 / k, rng.random_range(0.0..std::f64::consts::TAU)));
        }
    }
    let mut out = vec![0.0; SIZE * SIZE];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (u, v) = (x as f64 / SIZE as f64, y as f64 / SIZE as f64);
            out[y * SIZE + x] =
                waves.iter().map(|&(m, n, a, p)| a * (std::f64::consts::TAU * (m * u + n * v) + p).cos()).sum();
        }
    }
    let sd = (out.iter().map(|v| v * v).sum::<f64>() / out.len() as f64).sqrt();
    out.iter_mut().for_each(|v| *v /= sd);
    out
}

fn main() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261122);
    let patches = tileable(&mut rng, 1.0, 4.0, 24);
    let medium = tileable(&mut rng, 4.0, 12.0, 60);
    let ridges = tileable(&mut rng, 10.0, 28.0, 90);
    let grain = tileable(&mut rng, 28.0, 60.0, 120);
    let deep = [10.0, 40.0, 62.0];
    let green = [14.0, 62.0, 70.0];
    let light = [36.0, 96.0, 112.0];
    let mut rgb = Vec::with_capacity(SIZE * SIZE * 3);
    for i in 0..SIZE * SIZE {
        // Broad patches move the hue between deep blue and blue-green.
        let hue = (0.5 + 0.25 * patches[i] + 0.12 * medium[i]).clamp(0.0, 1.0);
        // Ridged noise (1 - |n|) makes a net of thin bright lines.
        let ridge = (1.0 - ridges[i].abs()).max(0.0).powi(6);
        let bright = (0.18 * ridge + 0.05 * grain[i] + 0.06 * medium[i]).clamp(-0.2, 1.0);
        for c in 0..3 {
            let base = deep[c] + (green[c] - deep[c]) * hue;
            let v = base + (light[c] - base) * bright.max(0.0) + base * bright.min(0.0);
            rgb.push(v.round().clamp(0.0, 255.0) as u8);
        }
    }
    let out = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/sea_texture.png");
    let file = std::fs::File::create(out).unwrap();
    PngEncoder::new_with_quality(file, CompressionType::Best, FilterType::Adaptive)
        .write_image(&rgb, SIZE as u32, SIZE as u32, image::ExtendedColorType::Rgb8)
        .unwrap();
    println!("wrote {out}");
}
