//! The graphics-protocol encoders on the frames a 160x48-cell window with 8x16-pixel cells
//! shows (issue 15), against rendering the same frame:
//! - `graphics/render_pool_1280x752`: the pool scene rendering one frame (the baseline every
//!   protocol pays before encoding);
//! - `graphics/sixel_full_1280x750`: dither + encode a whole sixel picture (a start, a resize);
//! - `graphics/sixel_dither_1280x750`: the dither alone (part of both sixel figures);
//! - `graphics/sixel_next_1280x750`: the next frame after two simulation steps (dither, find the
//!   changed cells, encode them);
//! - `graphics/kitty_direct_1280x752`: zlib level 1 + base64 chunks of a whole frame;
//! - `graphics/kitty_direct_next_1280x752`: the next frame with frame edits (kitty itself): only
//!   the changed rectangle is compressed and sent;
//! - `graphics/kitty_direct_640x376`: the same at half the resolution (the terminal scales it
//!   to the same cells): what a remote or busy player falls back to;
//! - `graphics/kitty_tempfile_1280x752`: a whole frame through a file in /dev/shm (raw RGB);
//! - `graphics/iterm2_png_1280x752`: PNG + base64 of a whole frame;
//! - `graphics/rgb_1280x752`: the pixmap -> RGB copy kitty needs first.
//!
//! The bytes each frame takes, and zlib levels 1 and 6 compared, are printed before the timings.
//!
//!     cargo bench --bench graphics
//!
//! For figures to quote, pin to one core: `RAYON_NUM_THREADS=1 taskset -c 0 cargo bench --bench
//! graphics`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use tidepool::play::GraphicsMode;
use tidepool::testing::Iterm2Encoder;
use tidepool::testing::push_rgb;
use tidepool::testing::{KittyEncoder, KittyOptions, Medium, kitty_temp_dir as temp_dir};
use tidepool::testing::{Layout, layout};
use tidepool::testing::{SixelEncoder, SixelPalette};
use tidepool::{Damping, PoolScene, PoolSettings, Scene, Stone};
use tiny_skia::Pixmap;

const TERM: (u16, u16) = (160, 48);
const CELL_PX: (u16, u16) = (8, 16);

fn scene(w: u32, h: u32) -> PoolScene {
    let damping = Damping::from_shift(4).unwrap();
    let settings = PoolSettings { damping, rain_rate: 0.02, seed: 1, ..PoolSettings::default() };
    let mut scene = PoolScene::new(w, h, settings).unwrap();
    for (i, (x, y)) in [(300, 200), (900, 500), (640, 400)].into_iter().enumerate() {
        scene.drop_stone(Stone::clamped(x, y, 12, 64));
        for _ in 0..40 * (i + 1) {
            Scene::advance(&mut scene, 1);
        }
    }
    scene
}

fn frames(w: u32, h: u32) -> (Pixmap, Pixmap) {
    let mut scene = scene(w, h);
    let mut a = Pixmap::new(w, h).unwrap();
    scene.render(&mut a);
    Scene::advance(&mut scene, 1);
    Scene::advance(&mut scene, 1);
    let mut b = Pixmap::new(w, h).unwrap();
    scene.render(&mut b);
    (a, b)
}

fn rgb(p: &Pixmap) -> Vec<u8> {
    let mut v = Vec::new();
    push_rgb(p, &mut v);
    v
}

fn graphics(c: &mut Criterion) {
    let sixel = layout(GraphicsMode::Sixel, TERM, Some(CELL_PX), Some((4096, 4096)), Layout::SCALED_CAP);
    let kitty = layout(GraphicsMode::Kitty, TERM, Some(CELL_PX), None, Layout::SCALED_CAP);
    let (sw, sh) = sixel.picture;
    let (kw, kh) = kitty.picture;
    let (sa, sb) = frames(sw, sh);
    let (ka, kb) = frames(kw, kh);
    let (sa, sb) = (rgb(&sa), rgb(&sb));
    let (ka_rgb, kb_rgb) = (rgb(&ka), rgb(&kb));

    // Bytes per frame, printed once.
    // The palette fitted to the first frame, as the stream fits it to the scene.
    let palette = SixelPalette::fit(&sa, 3, 256);
    let mut out = Vec::with_capacity(8 << 20);
    let mut enc = SixelEncoder::new(palette.clone(), (0, 0), Some(CELL_PX));
    enc.encode(&sa, sw, sh, &mut out);
    let sixel_full = out.len();
    out.clear();
    let update = enc.encode(&sb, sw, sh, &mut out);
    println!("sixel {sw}x{sh}: whole frame {sixel_full} bytes; next frame {update:?} {} bytes", out.len());
    out.clear();
    let mut kenc = KittyEncoder::new(KittyOptions { frame_edits: true, ..KittyOptions::new(kitty.cells) });
    kenc.encode(&ka_rgb, kw, kh, &mut out).unwrap();
    println!("kitty direct {kw}x{kh}: whole frame {} bytes", out.len());
    out.clear();
    let update = kenc.encode(&kb_rgb, kw, kh, &mut out).unwrap();
    println!(
        "kitty direct {kw}x{kh}, frame edits: next frame {update:?} {} bytes (with frame edits off: whole)",
        out.len()
    );
    out.clear();
    let mut it = Iterm2Encoder::new((0, 0), kitty.cells, false);
    it.encode(&ka, &mut out);
    println!("iterm2 {kw}x{kh}: whole frame {} bytes", out.len());

    {
        for level in [1, 6] {
            let mut best = std::time::Duration::MAX;
            let mut size = 0;
            for _ in 0..5 {
                let t = std::time::Instant::now();
                let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::new(level));
                std::io::Write::write_all(&mut z, &kb_rgb).unwrap();
                size = z.finish().unwrap().len();
                best = best.min(t.elapsed());
            }
            println!("zlib level {level} of {} RGB bytes: {size} bytes, best of 5 {best:?}", kb_rgb.len());
        }
    }
    let mut group = c.benchmark_group("graphics");
    group.sample_size(20);
    group.bench_function("render_pool_1280x752", |b| {
        let mut s = scene(kw, kh);
        let mut p = Pixmap::new(kw, kh).unwrap();
        b.iter(|| s.render(black_box(&mut p)))
    });
    group.bench_function("rgb_1280x752", |b| {
        let mut v = Vec::with_capacity(kw as usize * kh as usize * 3);
        b.iter(|| {
            v.clear();
            push_rgb(black_box(&ka), &mut v)
        })
    });
    group.bench_function("sixel_full_1280x750", |b| {
        let mut enc = SixelEncoder::new(palette.clone(), (0, 0), Some(CELL_PX));
        b.iter(|| {
            out.clear();
            enc.invalidate();
            enc.encode(black_box(&sa), sw, sh, &mut out)
        })
    });
    group.bench_function("sixel_dither_1280x750", |b| {
        let mut enc = SixelEncoder::new(palette.clone(), (0, 0), Some(CELL_PX));
        let mut idx = Vec::new();
        b.iter(|| enc.dither_into(black_box(&sa), sw, sh, &mut idx))
    });
    group.bench_function("sixel_next_1280x750", |b| {
        let mut enc = SixelEncoder::new(palette.clone(), (0, 0), Some(CELL_PX));
        let mut flip = false;
        b.iter(|| {
            out.clear();
            flip = !flip;
            enc.encode(black_box(if flip { &sa } else { &sb }), sw, sh, &mut out)
        })
    });
    group.bench_function("kitty_direct_1280x752", |b| {
        let mut enc = KittyEncoder::new(KittyOptions::new(kitty.cells));
        b.iter(|| {
            out.clear();
            enc.invalidate();
            enc.encode(black_box(&kb_rgb), kw, kh, &mut out).unwrap()
        })
    });
    group.bench_function("kitty_direct_next_1280x752", |b| {
        let mut enc = KittyEncoder::new(KittyOptions { frame_edits: true, ..KittyOptions::new(kitty.cells) });
        let mut flip = false;
        b.iter(|| {
            out.clear();
            flip = !flip;
            enc.encode(black_box(if flip { &ka_rgb } else { &kb_rgb }), kw, kh, &mut out).unwrap()
        })
    });
    let half = (kw / 2, kh / 2);
    let (small, _) = frames(half.0, half.1);
    let small = rgb(&small);
    out.clear();
    KittyEncoder::new(KittyOptions::new(kitty.cells)).encode(&small, half.0, half.1, &mut out).unwrap();
    println!("kitty direct {}x{}: whole frame {} bytes", half.0, half.1, out.len());
    group.bench_function("kitty_direct_640x376", |b| {
        let mut enc = KittyEncoder::new(KittyOptions::new(kitty.cells));
        b.iter(|| {
            out.clear();
            enc.invalidate();
            enc.encode(black_box(&small), half.0, half.1, &mut out).unwrap()
        })
    });
    group.bench_function("kitty_tempfile_1280x752", |b| {
        let dir = temp_dir();
        let mut enc =
            KittyEncoder::new(KittyOptions { medium: Medium::TempFile(dir), ..KittyOptions::new(kitty.cells) });
        b.iter(|| {
            out.clear();
            enc.invalidate();
            enc.encode(black_box(&kb_rgb), kw, kh, &mut out).unwrap();
            // What the terminal does after reading: delete the file.
            std::fs::remove_file(temp_path(&out)).unwrap();
        })
    });
    group.bench_function("iterm2_png_1280x752", |b| {
        let mut enc = Iterm2Encoder::new((0, 0), kitty.cells, false);
        b.iter(|| {
            out.clear();
            enc.invalidate();
            enc.encode(black_box(&kb), &mut out)
        })
    });
    group.finish();
}

/// The file a `t=t` command names (its payload is the base64 path).
fn temp_path(command: &[u8]) -> std::path::PathBuf {
    use base64::Engine;
    let start = command.windows(4).position(|w| w == b"t=t;").unwrap() + 4;
    let end = command.len() - 2;
    let path = base64::engine::general_purpose::STANDARD.decode(&command[start..end]).unwrap();
    std::path::PathBuf::from(String::from_utf8(path).unwrap())
}

criterion_group!(benches, graphics);
criterion_main!(benches);
