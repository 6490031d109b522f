//! Generates `assets/pool_floor.png`, the built-in pool floor: glazed tiles with grout, a little
//! colour variation from tile to tile, and two dark lane stripes that show the refraction well.
//!
//! Run once with `cargo run --release --example make_pool_floor`; the PNG is committed.

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;
const TILE: f32 = 64.0;
const GROUT: f32 = 5.0;

fn main() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261122);
    let mut pixmap = Pixmap::new(WIDTH, HEIGHT).unwrap();
    pixmap.fill(Color::from_rgba8(150, 176, 184, 255)); // grout
    let cols = (WIDTH as f32 / TILE).ceil() as i32;
    let rows = (HEIGHT as f32 / TILE).ceil() as i32;
    let lanes = [rows / 3, rows - 1 - rows / 3];
    for row in 0..rows {
        for col in 0..cols {
            let lane = lanes.contains(&row) && col > 1 && col < cols - 2;
            let (base_r, base_g, base_b) = if lane { (24.0, 58.0, 112.0) } else { (92.0, 188.0, 212.0) };
            let jitter: f32 = rng.random_range(-1.0..1.0);
            let tint: f32 = rng.random_range(-1.0..1.0);
            let colour = Color::from_rgba8(
                (base_r + 10.0 * jitter - 6.0 * tint).clamp(0.0, 255.0) as u8,
                (base_g + 12.0 * jitter).clamp(0.0, 255.0) as u8,
                (base_b + 10.0 * jitter + 6.0 * tint).clamp(0.0, 255.0) as u8,
                255,
            );
            let mut paint = Paint::default();
            paint.set_color(colour);
            let x = col as f32 * TILE + GROUT / 2.0;
            let y = row as f32 * TILE + GROUT / 2.0;
            let rect = Rect::from_xywh(x, y, TILE - GROUT, TILE - GROUT).unwrap();
            pixmap.fill_rect(rect, &paint, Transform::identity(), None);
            // A soft glaze highlight along the top-left edges of each tile.
            paint.set_color(Color::from_rgba8(255, 255, 255, 34));
            pixmap.fill_rect(Rect::from_xywh(x, y, TILE - GROUT, 3.0).unwrap(), &paint, Transform::identity(), None);
            pixmap.fill_rect(Rect::from_xywh(x, y, 3.0, TILE - GROUT).unwrap(), &paint, Transform::identity(), None);
        }
    }
    // Fine grain, so the floor is not perfectly flat colour.
    for p in pixmap.pixels_mut() {
        let n: i32 = rng.random_range(-2..=2);
        let c = |v: u8| (i32::from(v) + n).clamp(0, 255) as u8;
        *p = tiny_skia::PremultipliedColorU8::from_rgba(c(p.red()), c(p.green()), c(p.blue()), 255).unwrap();
    }
    let out = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/pool_floor.png");
    let rgb: Vec<u8> = pixmap.pixels().iter().flat_map(|p| [p.red(), p.green(), p.blue()]).collect();
    let file = std::fs::File::create(out).unwrap();
    PngEncoder::new_with_quality(file, CompressionType::Best, FilterType::Adaptive)
        .write_image(&rgb, WIDTH, HEIGHT, image::ExtendedColorType::Rgb8)
        .unwrap();
    println!("wrote {out}");
}
