//! The terminal encoder at 160x48 cells (a 160x94-pixel pool and a status line):
//! - `output/halfblock/full_frame_160x48`: a whole frame from nothing (start, resize);
//! - `output/halfblock/diff_frame_160x48`: one frame of rippling water against the last one;
//! - `player/render_encode_160x48`: what the player does per frame: two simulation steps,
//!   render, cells, diff encode (the issue asks for >= 120 of these a second on one core).
//!
//!     cargo bench --bench encoder
//!
//! Medians on the 2-core development machine, pinned to one core
//! (`RAYON_NUM_THREADS=1 taskset -c 0 cargo bench --bench encoder`): full frame 335 µs,
//! diff frame 42 µs, render + encode 462 µs (about 2,160 frames a second).

use std::hint::black_box;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use tidepool::terminal::{Color, ColorMode, EncodeOptions, Frame, Shown, encode_into};
use tidepool::{Damping, PoolScene, PoolSettings, Scene, Stone};
use tiny_skia::Pixmap;

const COLS: usize = 160;
const ROWS: usize = 48;

fn scene() -> PoolScene {
    let damping = Damping::from_shift(4).unwrap();
    let settings = PoolSettings { damping, rain_rate: 0.02, seed: 1, ..PoolSettings::default() };
    let mut scene = PoolScene::new(COLS as u32, 2 * (ROWS as u32 - 1), settings).unwrap();
    for (i, (x, y)) in [(30, 20), (120, 70), (80, 45)].into_iter().enumerate() {
        scene.drop_stone(Stone::clamped(x, y, 3, 64));
        for _ in 0..20 * (i + 1) {
            Scene::advance(&mut scene, 1);
        }
    }
    scene
}

fn frame(scene: &mut PoolScene, pixmap: &mut Pixmap) -> Frame {
    scene.render(pixmap);
    let mut f = Frame::new(COLS, ROWS);
    f.draw_pixels(pixmap, ColorMode::TrueColor);
    f.text(0, ROWS - 1, " pool \u{b7} 30 fps \u{b7} 12.3 kB/s", Color::Default, Color::Index(4));
    f
}

fn encoder(c: &mut Criterion) {
    let mut scene = scene();
    let mut pixmap = Pixmap::new(scene.width(), scene.height()).unwrap();
    let a = frame(&mut scene, &mut pixmap);
    Scene::advance(&mut scene, 1);
    Scene::advance(&mut scene, 1);
    let b = frame(&mut scene, &mut pixmap);
    let options = EncodeOptions::default();
    let mut shown_a = Shown::UNKNOWN;
    let mut out = Vec::with_capacity(1 << 20);
    encode_into(&mut shown_a, &a, options, &mut out);

    let mut group = c.benchmark_group("output/halfblock");
    group.bench_function("full_frame_160x48", |bench| {
        bench.iter(|| {
            let mut shown = Shown::UNKNOWN;
            out.clear();
            encode_into(&mut shown, black_box(&a), options, &mut out);
            out.len()
        })
    });
    group.bench_function("diff_frame_160x48", |bench| {
        bench.iter_batched(
            || shown_a.clone(),
            |mut shown| {
                out.clear();
                encode_into(&mut shown, black_box(&b), options, &mut out);
                out.len()
            },
            BatchSize::SmallInput,
        )
    });
    group.finish();

    let mut group = c.benchmark_group("player");
    let mut shown = shown_a.clone();
    let mut n = 0u32;
    group.bench_function("render_encode_160x48", |bench| {
        bench.iter(|| {
            n += 1;
            if n.is_multiple_of(30) {
                scene.drop_stone(Stone::clamped((n * 37 % 160) as i32, (n * 17 % 94) as i32, 3, 64));
            }
            Scene::advance(&mut scene, 1);
            Scene::advance(&mut scene, 1);
            let f = frame(&mut scene, &mut pixmap);
            out.clear();
            encode_into(&mut shown, &f, options, &mut out);
            out.len()
        })
    });
    group.finish();
}

criterion_group!(benches, encoder);
criterion_main!(benches);
