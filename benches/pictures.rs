//! Pictures at a rate (issue 22): which mode shows the truer moving picture at a link's rate.
//!
//! The scene: the codec fixture's session (`tests/fixtures/alive-160x48.jsonl`: the alive pool,
//! breeze, rain, a stone about every second) re-simulated at the size a pixel mode renders the
//! pool at in a 160x48 terminal of 8x16-pixel cells (480x282: the player's scene cap), its
//! stones scaled to that grid; a frame every two steps (30 fps). The truth at each display
//! instant is that picture resampled to the cell area's pixel size (1280x752).
//!
//! For each mode (kitty, sixel, iTerm2 through [`PictureStream`]; half-block cells through the
//! cell codec, `RateEncoder` with a `ByteBucket`, as `benches/codec.rs` drives it) at 50 kB/s,
//! 250 kB/s, 2 MB/s and unlimited, on a simulated 30 fps clock: every offer is committed and
//! decoded as the terminal would show it (kitty by the project's decoder, sixel by icy_sixel
//! onto a screen-sized canvas at its cell, iTerm2's PNG/JPEG by `image`; cells through the
//! terminal model), scaled to 1280x752 the way the terminal scales it (kitty and iTerm2:
//! resampled; sixel: already one pixel a pixel; cells: 8x8 pixels a half block), and compared
//! with the truth by SSIM of luma (`tidepool::testing::ssim`) every sixth frame (5 times a
//! second). Reported: pictures a second, bytes a second, mean and 5th-percentile SSIM, and the
//! median time the stream (or the cell encoder) took per frame on this machine.
//!
//! Then criterion measures the stream's per-frame encode time without a rate limit (kitty and
//! iTerm2 at 30 fps, sixel at 15 fps: the CPU targets).
//!
//!     cargo bench --bench pictures               # the table, then the CPU figures
//!     PICTURES=table cargo bench --bench pictures
//!     PICTURES=table PICTURES_MODES=sixel,cells cargo bench --bench pictures   # some modes
//!     PICTURES=cpu cargo bench --bench pictures
//!     PICTURES=table PICTURES_PHASE=4 cargo bench --bench pictures   # SSIM on sixel's frames
//!     PICTURES=table PICTURES_RATES=4e6,8e6,unlimited cargo bench --bench pictures   # other rates

use std::hint::black_box;
use std::time::{Duration, Instant};

use base64::Engine;
use criterion::Criterion;
use tidepool::play::ColorMode;
use tidepool::play::GraphicsMode;
use tidepool::testing::ByteBucket;
use tidepool::testing::KittyOptions;
use tidepool::testing::Script;
use tidepool::testing::{
    Budget, KittyState, Luma, PictureStream, Protocol, RateEncoder, RateOptions, Target, TerminalModel,
};
use tidepool::testing::{Color, Frame, Shown};
use tidepool::testing::{Layout, layout};
use tidepool::testing::{Registers, SixelPalette};
use tidepool::{Event, Stone};
use tiny_skia::Pixmap;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/alive-160x48.jsonl");
const TERM: (u16, u16) = (160, 48);
const CELL_PX: (u16, u16) = (8, 16);
/// The scene a pixel mode renders at 160x48 cells (the player's 480x300 cap of 1280x752).
const SCENE: (u32, u32) = (480, 282);
/// The cell area's pixel size: where SSIM is measured.
const AREA: (u32, u32) = (1280, 752);
const FPS: u32 = 30;
const STEPS_PER_FRAME: u64 = 2;
/// SSIM every this many frames.
const SAMPLE_EVERY: usize = 6;
const RATES: [Option<f64>; 4] = [Some(50e3), Some(250e3), Some(2e6), None];

/// The rates the table is made at: [`RATES`] unless `PICTURES_RATES` lists others (bytes a
/// second, comma-separated, `unlimited` for no limit), to find where a mode overtakes cells.
fn rates() -> Vec<Option<f64>> {
    let Ok(list) = std::env::var("PICTURES_RATES") else { return RATES.to_vec() };
    list.split(',')
        .map(|r| match r.trim() {
            "unlimited" => None,
            r => Some(r.parse::<f64>().unwrap_or_else(|_| panic!("PICTURES_RATES: {r:?} is not bytes a second"))),
        })
        .collect()
}
const MODES: [&str; 4] = ["kitty", "sixel", "iterm2", "cells"];

/// The fixture at the pixel modes' scene size: one picture per frame.
fn pictures() -> Vec<Pixmap> {
    let replay = tidepool::replay::Replay::read(std::path::Path::new(FIXTURE)).expect("the committed fixture replay");
    let [w0, _] = replay.size();
    let scale = f64::from(SCENE.0) / f64::from(w0);
    let mut scene = replay.spec(tidepool::PoolSettings::default_floor()).build(SCENE.0, SCENE.1).expect("a valid size");
    let events: Vec<(u64, Event)> = replay
        .script()
        .into_iter()
        .map(|(step, e)| match e {
            Event::Stone(s) => {
                let v = |x: i32| (f64::from(x) * scale).round() as i64;
                let radius = (f64::from(s.radius()) * scale).round() as i64;
                (step, Event::Stone(Stone::new(v(s.x()), v(s.y()), radius, i64::from(s.weight())).expect("a stone")))
            }
            e => (step, e),
        })
        .collect();
    let mut script = Script::new(&events);
    let mut out = Vec::new();
    let mut step = 0;
    while step + STEPS_PER_FRAME <= replay.end_step() {
        step += STEPS_PER_FRAME;
        script.run_to(scene.as_mut(), step);
        out.push(scene.snapshot().expect("a valid size"));
    }
    out
}

/// RGB of `size` as luma, resampled to `to` by a tent filter (what kitty and iTerm2 do when
/// they scale an image to its cells) or by repeating pixels (`nearest`).
fn luma_at(rgb: &[u8], size: (u32, u32), to: (u32, u32), nearest: bool) -> Luma {
    if nearest {
        let (w, h) = (size.0 as usize, size.1 as usize);
        return Luma::from_fn(to.0 as usize, to.1 as usize, |x, y| {
            let (sx, sy) = (x * w / to.0 as usize, y * h / to.1 as usize);
            let i = 3 * (sy * w + sx);
            [rgb[i], rgb[i + 1], rgb[i + 2]]
        });
    }
    let mut out = Vec::new();
    tidepool::testing::resample(rgb, 3, size, to, &mut out);
    Luma::of_rgb(to.0 as usize, to.1 as usize, &out)
}

/// What the terminal shows of a pixel mode, fed the offers.
enum Terminal {
    Kitty(KittyState),
    /// The last inline file decoded (RGB at its size).
    Iterm2(Option<(u32, u32, Vec<u8>)>),
    /// The screen's pixels (RGB, 1280x750) painted by each sixel image at its cell.
    Sixel(Vec<u8>, (u32, u32)),
}

impl Terminal {
    fn feed(&mut self, bytes: &[u8]) {
        match self {
            Terminal::Kitty(state) => state.feed(bytes).expect("kitty stream decodes"),
            Terminal::Iterm2(shown) => {
                let start = bytes.windows(5).position(|w| w == b"1337;").expect("an inline image");
                let colon = start + bytes[start..].iter().position(|&b| b == b':').expect("args end");
                let end = colon + bytes[colon..].iter().position(|&b| b == 7).expect("BEL");
                let file = base64::engine::general_purpose::STANDARD.decode(&bytes[colon + 1..end]).expect("base64");
                let image = image::load_from_memory(&file).expect("PNG or JPEG").to_rgb8();
                *shown = Some((image.width(), image.height(), image.into_raw()));
            }
            Terminal::Sixel(canvas, size) => {
                let mut rest = bytes;
                while let Some(at) = rest.windows(2).position(|w| w == b"\x1b[") {
                    let h = rest[at..].iter().position(|&b| b == b'H').expect("a cursor move");
                    let text = std::str::from_utf8(&rest[at + 2..at + h]).unwrap();
                    let (row, col) = text.split_once(';').unwrap();
                    let (row, col): (u32, u32) = (row.parse().unwrap(), col.parse().unwrap());
                    let body = &rest[at + h + 1..];
                    let end = body.windows(2).position(|w| w == b"\x1b\\").expect("a terminated image") + 2;
                    let image = icy_sixel::SixelImage::decode(&body[..end]).expect("icy_sixel decodes");
                    let (x0, y0) = ((col - 1) * u32::from(CELL_PX.0), (row - 1) * u32::from(CELL_PX.1));
                    for y in 0..image.height {
                        for x in 0..image.width {
                            let p = &image.pixels[(y * image.width + x) * 4..][..4];
                            let (cx, cy) = (x0 as usize + x, y0 as usize + y);
                            if p[3] == 255 && cx < size.0 as usize && cy < size.1 as usize {
                                canvas[(cy * size.0 as usize + cx) * 3..][..3].copy_from_slice(&p[..3]);
                            }
                        }
                    }
                    rest = &body[end..];
                }
            }
        }
    }

    /// What is shown: RGB at its size, and whether the terminal repeats its pixels (sixel).
    fn rgb(&self) -> Option<(u32, u32, &[u8], bool)> {
        match self {
            Terminal::Kitty(state) => {
                let image = state.images.get(&KittyOptions::IMAGE_ID)?;
                Some((image.width, image.height, &image.rgb, false))
            }
            Terminal::Iterm2(shown) => shown.as_ref().map(|(w, h, rgb)| (*w, *h, &rgb[..], false)),
            Terminal::Sixel(canvas, size) => Some((size.0, size.1, &canvas[..], true)),
        }
    }

    fn luma(&self) -> Option<Luma> {
        match self {
            Terminal::Kitty(state) => {
                let image = state.images.get(&KittyOptions::IMAGE_ID)?;
                Some(luma_at(&image.rgb, (image.width, image.height), AREA, false))
            }
            Terminal::Iterm2(shown) => shown.as_ref().map(|(w, h, rgb)| luma_at(rgb, (*w, *h), AREA, false)),
            Terminal::Sixel(canvas, size) => Some(luma_at(canvas, *size, *size, true)),
        }
    }
}

fn stream(mode: &str) -> (PictureStream, Terminal) {
    let l = |m| layout(m, TERM, Some(CELL_PX), Some((4096, 4096)), Layout::SCALED_CAP);
    match mode {
        "kitty" => {
            let l = l(GraphicsMode::Kitty);
            let options = KittyOptions { frame_edits: true, ..KittyOptions::new(l.cells) };
            (PictureStream::new(Protocol::Kitty(options), l), Terminal::Kitty(Default::default()))
        }
        "sixel" => {
            let l = l(GraphicsMode::Sixel);
            let protocol = Protocol::Sixel {
                palette: SixelPalette::for_registers(256),
                registers: Registers::PerImage,
                tmux: false,
            };
            let canvas = vec![0u8; l.picture.0 as usize * l.picture.1 as usize * 3];
            (PictureStream::new(protocol, l), Terminal::Sixel(canvas, l.picture))
        }
        _ => {
            let l = l(GraphicsMode::Iterm2);
            (PictureStream::new(Protocol::Iterm2 { tmux: false }, l), Terminal::Iterm2(None))
        }
    }
}

struct Row {
    /// The rung the run ended on.
    rung: String,
    pictures: usize,
    bytes: usize,
    ssim: Vec<f64>,
    times: Vec<Duration>,
}

fn run(mode: &str, rate: Option<f64>, shots: &[Pixmap], truths: &[Luma]) -> Row {
    let t0 = Instant::now();
    let frame = Duration::from_nanos(1_000_000_000 / u64::from(FPS));
    let mut bucket = rate.map_or_else(ByteBucket::unlimited, ByteBucket::new);
    bucket.refill(t0);
    let mut row = Row { rung: "160x94 cells".into(), pictures: 0, bytes: 0, ssim: Vec::new(), times: Vec::new() };
    let phase = phase();
    let sample = |i: usize| i % SAMPLE_EVERY == phase;
    if mode == "cells" {
        let (cols, rows) = (usize::from(TERM.0), usize::from(TERM.1));
        let mut encoder = RateEncoder::new();
        let mut shown = Shown::UNKNOWN;
        let mut screen = TerminalModel::new(cols, rows);
        screen.lf_returns = false;
        let mut frame_cells = Frame::new(cols, rows);
        let mut small = Vec::new();
        let mut out = Vec::new();
        for (n, shot) in shots.iter().enumerate() {
            bucket.refill(t0 + frame * (n as u32 + 1));
            let budget = bucket.budget();
            let started = Instant::now();
            // The half-block picture: the scene at 160x94, as the player would render it.
            let (pw, ph) = (cols as u32, 2 * (rows as u32 - 1));
            tidepool::testing::resample(shot.data(), 4, SCENE, (pw, ph), &mut small);
            let mut pixmap = Pixmap::new(pw, ph).unwrap();
            for (px, p) in pixmap.pixels_mut().iter_mut().zip(small.chunks_exact(3)) {
                *px = tiny_skia::ColorU8::from_rgba(p[0], p[1], p[2], 255).premultiply();
            }
            frame_cells.draw_pixels(&pixmap, ColorMode::TrueColor);
            frame_cells.clear_row(rows - 1, Color::Index(4));
            out.clear();
            encoder.encode_into(&mut shown, Target::new(&frame_cells), budget, RateOptions::default(), &mut out);
            row.times.push(started.elapsed());
            bucket.spend(out.len());
            row.bytes += out.len();
            row.pictures += usize::from(!out.is_empty());
            screen.feed(&out);
            if sample(n) {
                let rgb: Vec<u8> = (0..ph as usize)
                    .flat_map(|y| (0..pw as usize).map(move |x| (x, y)))
                    .flat_map(|(x, y)| screen.pixel(x, y).unwrap_or([0, 0, 0]))
                    .collect();
                if n / SAMPLE_EVERY == DUMP_SAMPLE {
                    dump(
                        &format!("cells-{}", rate.map_or("unlimited".into(), |r| format!("{:.0}k", r / 1e3))),
                        &rgb,
                        (pw, ph),
                        true,
                    );
                }
                let shown = luma_at(&rgb, (pw, ph), AREA, true);
                row.ssim.push(view_ssim(&shown, &truths[n]));
            }
        }
        return row;
    }
    let (mut stream, mut terminal) = stream(mode);
    for (n, shot) in shots.iter().enumerate() {
        let now = t0 + frame * (n as u32 + 1);
        bucket.refill(now);
        let budget = Budget::new(bucket.budget(), rate, frame);
        let started = Instant::now();
        let offer = stream.prepare(shot, budget, now).map(|o| o.bytes.to_vec());
        row.times.push(started.elapsed());
        if let Some(bytes) = offer {
            assert!(bytes.len() <= budget.available, "{mode}: an offer over the budget");
            stream.commit();
            bucket.spend(bytes.len());
            row.bytes += bytes.len();
            row.pictures += 1;
            terminal.feed(&bytes);
        }
        if sample(n) && n / SAMPLE_EVERY == DUMP_SAMPLE {
            let (w, h, rgb, nearest) = terminal.rgb().unwrap_or((1, 1, &[0, 0, 0], true));
            dump(
                &format!("{mode}-{}", rate.map_or("unlimited".into(), |r| format!("{:.0}k", r / 1e3))),
                rgb,
                (w, h),
                nearest,
            );
            dump(
                &format!("truth-{n}"),
                &shot.data().chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect::<Vec<u8>>(),
                SCENE,
                false,
            );
        }
        if sample(n) {
            let truth = &truths[n];
            // PICTURES_DEBUG: the mean luma error about two seconds in (a misplaced or missing picture
            // shows as tens of levels; sixel's dither alone is about 20, kitty's PNG 4).
            if std::env::var("PICTURES_DEBUG").is_ok()
                && n / SAMPLE_EVERY == 9
                && let Some(shown) = terminal.luma()
            {
                let (w, h) = (shown.width().min(truth.width()), shown.height().min(truth.height()));
                let mut sum = 0.0;
                for y in 0..h {
                    for x in 0..w {
                        sum += f64::from((shown.get(x, y) - truth.get(x, y)).abs());
                    }
                }
                eprintln!("{mode} {rate:?}: mean luma error {:.2} over {w}x{h}", sum / (w * h) as f64);
            }
            let s = match terminal.luma() {
                None => 0.0,
                Some(shown) if shown.height() == truth.height() => view_ssim(&shown, truth),
                // Sixel's whole bands end 2 rows above the area: the truth cut to them.
                Some(shown) => {
                    let cut = Luma::from_fn(shown.width(), shown.height(), |x, y| {
                        let v = truth.get(x, y).round() as u8;
                        [v, v, v]
                    });
                    view_ssim(&shown, &cut)
                }
            };
            row.ssim.push(s);
        }
    }
    let state = stream.state();
    row.rung = format!("{}x{} {}", state.size.0, state.size.1, state.packing.map_or("-".into(), |p| p.name()));
    row
}

/// The sample whose picture `PICTURES_DUMP` writes: about 6 s in (the stream long settled).
const DUMP_SAMPLE: usize = 30;

/// With `PICTURES_DUMP=dir`: writes `rgb` (`size`) as the terminal shows it at the cell area's
/// size (scaled as `luma_at` scales it) to `dir/name.png`, to look at.
fn dump(name: &str, rgb: &[u8], size: (u32, u32), nearest: bool) {
    let Ok(dir) = std::env::var("PICTURES_DUMP") else { return };
    let mut out = Vec::new();
    if nearest {
        let (w, h) = (size.0 as usize, size.1 as usize);
        for y in 0..AREA.1 as usize {
            for x in 0..AREA.0 as usize {
                let i = 3 * (y * h / AREA.1 as usize * w + x * w / AREA.0 as usize);
                out.extend_from_slice(&rgb[i..i + 3]);
            }
        }
    } else {
        tidepool::testing::resample(rgb, 3, size, AREA, &mut out);
    }
    let path = std::path::Path::new(&dir).join(format!("{name}.png"));
    image::save_buffer(&path, &out, AREA.0, AREA.1, image::ExtendedColorType::Rgb8)
        .expect("PICTURES_DUMP: the picture is written");
}

/// SSIM of `a` against `b`, both first averaged over `PICTURES_VIEW`-pixel squares when that
/// is set (a viewing distance at which single screen pixels blur: dither patterns average out).
fn view_ssim(a: &Luma, b: &Luma) -> f64 {
    let k: usize = std::env::var("PICTURES_VIEW").ok().and_then(|v| v.parse().ok()).unwrap_or(1).max(1);
    if k == 1 {
        return tidepool::testing::ssim(a, b);
    }
    let shrink = |l: &Luma| {
        Luma::from_fn(l.width() / k, l.height() / k, |x, y| {
            let mut sum = 0.0;
            for dy in 0..k {
                for dx in 0..k {
                    sum += f64::from(l.get(x * k + dx, y * k + dy));
                }
            }
            let v = (sum / (k * k) as f64).round().clamp(0.0, 255.0) as u8;
            [v, v, v]
        })
    };
    tidepool::testing::ssim(&shrink(a), &shrink(b))
}

/// The frame of each `SAMPLE_EVERY` that SSIM is measured on: the last unless `PICTURES_PHASE`
/// says otherwise. Sixel pictures go at 15 a second, on even frames: on the default (odd)
/// frames sixel always shows the frame before the truth, `PICTURES_PHASE=4` measures the
/// frames it draws.
fn phase() -> usize {
    std::env::var("PICTURES_PHASE")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(SAMPLE_EVERY - 1, |p: usize| p % SAMPLE_EVERY)
}

fn percentile(values: &[f64], p: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn table() {
    let t = Instant::now();
    let shots = pictures();
    let truths: Vec<Luma> = shots
        .iter()
        .enumerate()
        .map(|(n, p)| {
            if n % SAMPLE_EVERY == phase() {
                let mut rgb = Vec::new();
                tidepool::testing::resample(p.data(), 4, SCENE, SCENE, &mut rgb);
                luma_at(&rgb, SCENE, AREA, false)
            } else {
                Luma::from_fn(0, 0, |_, _| [0, 0, 0])
            }
        })
        .collect();
    let seconds = shots.len() as f64 / f64::from(FPS);
    println!(
        "pictures fixture: {} frames ({seconds:.1} s at {FPS} fps) of the alive pool at {}x{}, SSIM at {}x{}, made in {:.1} s",
        shots.len(),
        SCENE.0,
        SCENE.1,
        AREA.0,
        AREA.1,
        t.elapsed().as_secs_f64()
    );
    println!();
    println!("| rate | mode | pictures/s | sent kB/s | mean SSIM | 5th pct SSIM | median ms/frame | last rung |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut picks = Vec::new();
    for rate in rates() {
        let mut means = Vec::new();
        let label = rate.map_or("unlimited".to_string(), |r| format!("{:.0} kB/s", r / 1000.0));
        let only = std::env::var("PICTURES_MODES").unwrap_or_default();
        for mode in MODES.into_iter().filter(|m| only.is_empty() || only.split(',').any(|o| o == *m)) {
            let r = run(mode, rate, &shots, &truths);
            let mut times = r.times.clone();
            times.sort();
            let mean = r.ssim.iter().sum::<f64>() / r.ssim.len() as f64;
            let rung = &r.rung;
            means.push((mode, mean));
            println!(
                "| {label} | {mode} | {:.1} | {:.1} | {mean:.4} | {:.4} | {:.2} | {rung} |",
                r.pictures as f64 / seconds,
                r.bytes as f64 / seconds / 1000.0,
                percentile(&r.ssim, 0.05),
                times[times.len() / 2].as_secs_f64() * 1000.0,
            );
        }
        let cells = means.iter().find(|(m, _)| *m == "cells").map_or(0.0, |(_, v)| *v);
        let choice: Vec<String> = means
            .iter()
            .filter(|(m, _)| *m != "cells")
            .map(|(m, v)| format!("{m}: {}", if *v > cells { *m } else { "cells" }))
            .collect();
        picks.push(format!("{label}: {}", choice.join(", ")));
    }
    println!();
    println!("the truer mode at each rate (what `auto` should pick for a terminal of each protocol):");
    for p in picks {
        println!("- {p}");
    }
    println!();
    println!("table made in {:.1} s", t.elapsed().as_secs_f64());
}

fn cpu(c: &mut Criterion) {
    let shots = pictures();
    let mut group = c.benchmark_group("pictures/stream_frame_160x48_unlimited");
    group.sample_size(20);
    for mode in ["kitty", "sixel", "iterm2"] {
        let (mut stream, _) = stream(mode);
        let frame = Duration::from_nanos(1_000_000_000 / 30);
        let t0 = Instant::now();
        let mut n = 0u32;
        group.bench_function(mode, |b| {
            b.iter(|| {
                n += 1;
                // Each frame due (a clock far enough ahead), a new picture every call.
                let now = t0 + frame * (n * 4);
                let len = stream
                    .prepare(black_box(&shots[n as usize % shots.len()]), Budget::unlimited(frame), now)
                    .map_or(0, |o| o.bytes.len());
                stream.commit();
                len
            })
        });
    }
    group.finish();
    // kitty under a rate: the lossy PNG (`lossy_png`, step 24; kitty's packing until Round 10)
    // and the palette PNG of the scene's 480x282 picture alone, and the stream's whole frame
    // at 2 MB/s (resampling, the changed box, the palette PNG at the top rung, every frame a
    // new picture).
    let mut group = c.benchmark_group("pictures/kitty_lossy_480x282");
    group.sample_size(20);
    let rgbs: Vec<Vec<u8>> = shots
        .iter()
        .take(16)
        .map(|p| {
            let mut rgb = Vec::new();
            tidepool::testing::push_rgb(p, &mut rgb);
            rgb
        })
        .collect();
    let (mut n, mut out, mut pixels) = (0usize, Vec::new(), Vec::new());
    group.bench_function("lossy_png_step24", |b| {
        b.iter(|| {
            n += 1;
            pixels.clear();
            pixels.extend_from_slice(&rgbs[n % rgbs.len()]);
            tidepool::testing::lossy_png(black_box(&mut pixels), SCENE.0, SCENE.1, 24, &mut out);
            out.len()
        })
    });
    // The same with the encoder kept from picture to picture, as the stream keeps it.
    let mut encoder = tidepool::testing::LossyPngEncoder::default();
    group.bench_function("lossy_png_step24_kept", |b| {
        b.iter(|| {
            n += 1;
            pixels.clear();
            pixels.extend_from_slice(&rgbs[n % rgbs.len()]);
            encoder.encode(black_box(&mut pixels), SCENE.0, SCENE.1, 24, &mut out);
            out.len()
        })
    });
    // kitty's packing under a rate since Round 10: the palette PNG of 16 colours, the encoder
    // (and its fitted palette) kept as the stream keeps it.
    let mut palette = tidepool::testing::PalettePngEncoder::default();
    group.bench_function("palette_png_16_kept", |b| {
        b.iter(|| {
            n += 1;
            pixels.clear();
            pixels.extend_from_slice(&rgbs[n % rgbs.len()]);
            palette.encode(black_box(&mut pixels), SCENE.0, SCENE.1, 16, &mut out);
            out.len()
        })
    });
    let (mut stream, _) = stream("kitty");
    let frame = Duration::from_nanos(1_000_000_000 / 30);
    let t0 = Instant::now();
    let mut n = 0u32;
    group.bench_function("stream_frame_2MBps", |b| {
        b.iter(|| {
            n += 1;
            let now = t0 + frame * (n * 4);
            let budget = Budget::new(usize::MAX, Some(2e6), frame);
            let len =
                stream.prepare(black_box(&shots[n as usize % shots.len()]), budget, now).map_or(0, |o| o.bytes.len());
            stream.commit();
            len
        })
    });
    group.finish();
}

fn main() {
    let only = std::env::var("PICTURES").unwrap_or_default();
    if only != "cpu" {
        table();
    }
    if only == "table" {
        return;
    }
    let mut criterion = Criterion::default().configure_from_args();
    cpu(&mut criterion);
    criterion.final_summary();
}
