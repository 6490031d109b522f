//! The terminal encoder measured like a codec (issue 14 §5, issue 21 §2).
//!
//! Four clips of 160x48 cells (160x94 pixels and a status line), as the player shows them:
//! - **pool**: `tests/fixtures/pool-160x48.jsonl`, the player's defaults, a stone a second
//!   after a 4 s warm-up (recorded in tmux by `scripts/record_pool_fixtures.sh`), re-simulated
//!   exactly from the replay;
//! - **pool, stones**: `tests/fixtures/pool-stones-160x48.jsonl`, the same with a stone every
//!   half second;
//! - **ocean B6**: the replay format holds the pool only, so the sea is a scripted scene: the
//!   player's ocean (one sample a pixel, the default camera and sun, seed 1) at Beaufort 6
//!   (12.3 m/s from 330°), advanced at its own 60 steps a second from t = 0, a frame every two
//!   steps: the same frames as `tidepool render ocean --beaufort 6 --ssaa 1 --size 160x94
//!   --frames 300 --fps 30`;
//! - **lake**: the player's lake (3 m/s, seed 1, one sample a pixel) at its 30 steps a second,
//!   a frame a step: `tidepool render lake --ssaa 1 --size 160x94 --frames 300 --fps 30`.
//!
//! Each clip is encoded at 25, 50, 100, 250 and 500 kB/s and unlimited, in truecolor and in
//! 256 colours, by three strategies in the same run: the shipped rate-controlled encoder
//! ([`tidepool::testing::RateEncoder`]), changed cells in scan order until the budget runs out
//! (the same encoder with [`Strategy::ScanOrder`]), and whole exact frames as often as the link
//! allows (best of colour quantization steps 1, 8, 16 and 32: colours rounded to multiples of
//! the step before the frame is drawn, so fewer cells change and more colour codes repeat). The
//! budgeted strategies take what a [`ByteBucket`] at the rate allows on a simulated 30 fps clock;
//! a whole frame goes when the link has carried the previous one and shows when it has arrived
//! (`bytes / rate` later). Every emitted byte goes through the terminal model
//! ([`tidepool::testing::TerminalModel`], exactly 160x48) and the screen is compared with the true
//! frame at each display instant: SSIM of luma ([`tidepool::testing::ssim`], Gaussian window of
//! 1.5) and PSNR (8-bit sRGB, both halves of every picture cell, an exact frame counted as
//! 99 dB), the status row left out.
//!
//! Then criterion measures the encoder's CPU per frame at 160x48 on the pool clip.
//!
//!     cargo bench --bench codec                # the table, then the CPU figures
//!     CODEC=table cargo bench --bench codec    # the table only (a few minutes)
//!     CODEC=cpu cargo bench --bench codec      # the CPU figures only
//!     CODEC=stale cargo bench --bench codec    # PSNR and SSIM of the true frame k frames late
//!     CODEC=quick cargo bench --bench codec    # the shipped encoder on the pool clip, for tuning
//!                                              # (CODEC_MODE=256, CODEC_CLIPS, CODEC_SERIES=1)
//!
//! `CODEC_CLIPS=pool,lake` limits the table to some clips (names: pool, stones, ocean, lake);
//! `CODEC_POOL=FILE` replaces the pool clip's replay (to try other looks on the same session:
//! edit a copy's header); `CODEC_SERIES=1` with `CODEC=quick` prints SSIM second by second,
//! the shipped encoder's and the scan-order baseline's.

use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use criterion::Criterion;
use tidepool::play::{ColorMode, EncodeOptions};
use tidepool::testing::ByteBucket;
use tidepool::testing::Script;
use tidepool::testing::{
    self as quality, Luma, RateEncoder, RateOptions, SsimReference, Strategy, Target, TerminalModel, UNLIMITED,
};
use tidepool::testing::{Color, Frame, Shown};
use tidepool::{LakeParams, LakeSettings, OceanSettings, OceanView, SceneSpec};
use tiny_skia::Pixmap;

const COLS: usize = 160;
const ROWS: usize = 48;
const FPS: u32 = 30;
/// The picture's size: every row but the status line, two pixels a row.
const PICTURE: (u32, u32) = (COLS as u32, 2 * (ROWS as u32 - 1));
/// Budgets in bytes per second; `None` is unlimited.
const BUDGETS: [Option<f64>; 6] = [Some(25e3), Some(50e3), Some(100e3), Some(250e3), Some(500e3), None];
/// The colour quantization steps the whole-frame baseline tries.
const QUANTIZATION_STEPS: [u8; 4] = [1, 8, 16, 32];
/// Frames of the scripted clips (10 s at 30 fps).
const SCRIPTED_FRAMES: usize = 300;

fn fixture(name: &str) -> String {
    if name == "pool-160x48.jsonl"
        && let Ok(path) = std::env::var("CODEC_POOL")
    {
        return path;
    }
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Counts allocations, to check that the encoder's steady state allocates nothing.
struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// A clip: the true pictures at each display instant, with what the truth's SSIM needs.
struct Clip {
    name: &'static str,
    pictures: Vec<Pixmap>,
    references: Vec<SsimReference>,
}

impl Clip {
    fn new(name: &'static str, pictures: Vec<Pixmap>) -> Clip {
        let references = pictures.iter().map(|p| SsimReference::new(&Luma::of_pixmap(p))).collect();
        Clip { name, pictures, references }
    }

    fn seconds(&self) -> f64 {
        self.pictures.len() as f64 / f64::from(FPS)
    }

    /// The frame the player would send for picture `k` in `mode`, its colours first rounded
    /// to multiples of `step`, with a status line.
    fn frame(&self, k: usize, mode: ColorMode, step: u8) -> Frame {
        let mut frame = Frame::new(COLS, ROWS);
        if step <= 1 {
            frame.draw_pixels(&self.pictures[k], mode);
        } else {
            frame.draw_pixels(&quantized(&self.pictures[k], step), mode);
        }
        let status = format!(" {} \u{b7} 30 fps \u{b7} {:.1} s", self.name, k as f64 / f64::from(FPS));
        frame.clear_row(ROWS - 1, Color::Index(4));
        frame.text(0, ROWS - 1, &status, Color::Index(15), Color::Index(4));
        frame
    }
}

/// `picture` with every channel rounded to the nearest multiple of `step` (at most 255).
fn quantized(picture: &Pixmap, step: u8) -> Pixmap {
    let mut out = picture.clone();
    let step = u16::from(step);
    for p in out.pixels_mut() {
        let c = p.demultiply();
        let q = |v: u8| ((u16::from(v) + step / 2) / step * step).min(255) as u8;
        *p = tiny_skia::ColorU8::from_rgba(q(c.red()), q(c.green()), q(c.blue()), 255).premultiply();
    }
    out
}

/// A pool clip: the replay re-simulated, a picture at every 30 fps display instant.
fn pool_clip(name: &'static str, file: &str) -> Clip {
    let replay =
        tidepool::replay::Replay::read(std::path::Path::new(&fixture(file))).expect("a committed fixture replay");
    assert_eq!(replay.size(), [PICTURE.0, PICTURE.1], "a 160x48-cell recording");
    let mut scene =
        replay.spec(tidepool::PoolSettings::default_floor()).build(PICTURE.0, PICTURE.1).expect("a valid size");
    let events = replay.script();
    let mut script = Script::new(&events);
    let per_second = scene.steps_per_second();
    let mut pictures = Vec::new();
    for k in 1.. {
        // The step shown at display instant k, as animations and the player's clock count.
        let step = (k as f64 * per_second / f64::from(FPS)).floor() as u64;
        if step > replay.end_step() {
            break;
        }
        script.run_to(scene.as_mut(), step);
        pictures.push(scene.snapshot().expect("a valid size"));
    }
    Clip::new(name, pictures)
}

/// A scripted clip: `spec` from its start, a picture at every 30 fps display instant (as
/// `tidepool render ... --frames` takes them: step floor(k · steps a second / 30)).
fn scripted_clip(name: &'static str, spec: SceneSpec) -> Clip {
    let mut scene = spec.build(PICTURE.0, PICTURE.1).expect("a valid size");
    let per_second = scene.steps_per_second();
    let mut step = 0;
    let mut pictures = Vec::new();
    for k in 0..SCRIPTED_FRAMES {
        let wanted = (k as f64 * per_second / f64::from(FPS)).floor() as u64;
        scene.advance(wanted - step);
        step = wanted;
        pictures.push(scene.snapshot().expect("a valid size"));
    }
    Clip::new(name, pictures)
}

/// The four clips (or those `CODEC_CLIPS` names).
fn clips() -> Vec<Clip> {
    let wanted = std::env::var("CODEC_CLIPS").unwrap_or_default();
    let take = |name: &str| wanted.is_empty() || wanted.split(',').any(|w| w.trim() == name);
    let mut clips = Vec::new();
    if take("pool") {
        clips.push(pool_clip("pool", "pool-160x48.jsonl"));
    }
    if take("stones") {
        clips.push(pool_clip("pool, stones", "pool-stones-160x48.jsonl"));
    }
    if take("ocean") {
        let wind = tidepool::sea::beaufort_speed_m_s(6).expect("Beaufort 6");
        let defaults = OceanSettings::default();
        let ocean = OceanSettings {
            sea: defaults.sea.with_wind_m_s(wind),
            view: OceanView { ssaa: 1, ..OceanView::default() },
            ..defaults
        };
        clips.push(scripted_clip("ocean B6", SceneSpec::Ocean(ocean)));
    }
    if take("lake") {
        let lake = LakeSettings { lake: LakeParams { seed: 1, ..LakeParams::default() }, ..LakeSettings::default() };
        clips.push(scripted_clip("lake", SceneSpec::Lake(lake)));
    }
    clips
}

/// How a run sends frames.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Sender {
    /// The rate-controlled encoder with this order (approximations with the shipped order).
    Rate(Strategy),
    /// Whole exact frames of colours rounded to this step, as often as the link allows.
    Whole(u8),
}

/// The numbers of one run.
#[derive(Clone, Debug, Default)]
struct Run {
    bytes: usize,
    ssim: Vec<f64>,
    psnr: Vec<f64>,
    exact_frames: usize,
    max_over_bucket: isize,
}

impl Run {
    fn mean(values: &[f64]) -> f64 {
        values.iter().sum::<f64>() / values.len().max(1) as f64
    }
}

/// The screen compared with the truth at display instant `k`.
fn score(run: &mut Run, clip: &Clip, k: usize, screen: &TerminalModel) {
    let (w, h) = (PICTURE.0 as usize, PICTURE.1 as usize);
    run.ssim.push(clip.references[k].ssim(&quality::screen_luma(screen, w, h)));
    let q = quality::measure(screen, &clip.pictures[k]);
    run.psnr.push(q.psnr());
    run.exact_frames += usize::from(q.mse == 0.0);
}

fn run(clip: &Clip, frames: &[Frame], mode: ColorMode, rate: Option<f64>, sender: Sender) -> Run {
    let mut screen = TerminalModel::new(COLS, ROWS);
    screen.lf_returns = false;
    let mut shown = Shown::UNKNOWN;
    let mut out = Vec::new();
    let mut result = Run { max_over_bucket: isize::MIN, ..Run::default() };
    match sender {
        Sender::Rate(strategy) => {
            let start = Instant::now();
            let mut bucket = rate.map_or_else(ByteBucket::unlimited, ByteBucket::new);
            bucket.refill(start);
            let mut encoder = RateEncoder::new();
            let options =
                RateOptions { strategy, approximate: strategy == Strategy::ErrorPerByte, ..RateOptions::default() };
            for (k, frame) in frames.iter().enumerate() {
                // The first frame at t = 0 finds an empty bucket: give it one frame's worth.
                bucket.refill(start + Duration::from_secs_f64((k + 1) as f64 / f64::from(FPS)));
                let budget = bucket.budget();
                out.clear();
                let target = match mode {
                    ColorMode::TrueColor => Target::new(frame),
                    _ => Target::with_truth(frame, &clip.pictures[k], mode),
                };
                encoder.encode_into(&mut shown, target, budget, options, &mut out);
                bucket.spend(out.len());
                if budget != UNLIMITED {
                    result.max_over_bucket = result.max_over_bucket.max(out.len() as isize - budget as isize);
                }
                result.bytes += out.len();
                screen.feed(&out);
                score(&mut result, clip, k, &screen);
            }
        }
        Sender::Whole(_) => {
            // The link is busy until `free` (in frames); a frame sent at k shows at `arrives`.
            let (mut free, mut pending): (f64, Option<(f64, Vec<u8>)>) = (0.0, None);
            for (k, frame) in frames.iter().enumerate() {
                let now = k as f64;
                if let Some((arrives, bytes)) = &pending
                    && *arrives <= now
                {
                    screen.feed(bytes);
                    pending = None;
                }
                if pending.is_none() && free <= now {
                    let mut bytes = Vec::new();
                    quality_exact(&mut shown, frame, &mut bytes);
                    let took = rate.map_or(0.0, |r| bytes.len() as f64 / r * f64::from(FPS));
                    result.bytes += bytes.len();
                    free = now + took;
                    if took <= 0.0 {
                        screen.feed(&bytes);
                    } else {
                        pending = Some((now + took, bytes));
                    }
                }
                score(&mut result, clip, k, &screen);
            }
        }
    }
    result
}

/// The bytes that show `frame` exactly after `shown`: today's diff encoder, which sends the
/// changed cells (a whole screen the first time).
fn quality_exact(shown: &mut Shown, frame: &Frame, out: &mut Vec<u8>) {
    tidepool::testing::encode_into(shown, frame, EncodeOptions::default(), out);
}

fn percentile(values: &[f64], p: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

/// One row of the table: a strategy's mean SSIM and PSNR at a budget.
struct Row {
    label: String,
    sent_kbps: f64,
    ssim: f64,
    psnr: f64,
    psnr_p5: f64,
    exact: (usize, usize),
}

impl Row {
    fn of(label: String, run: &Run, seconds: f64) -> Row {
        Row {
            label,
            sent_kbps: run.bytes as f64 / seconds / 1000.0,
            ssim: Run::mean(&run.ssim),
            psnr: Run::mean(&run.psnr),
            psnr_p5: percentile(&run.psnr, 0.05),
            exact: (run.exact_frames, run.ssim.len()),
        }
    }
}

fn table() {
    let t = Instant::now();
    let clips = clips();
    println!("clips made in {:.1} s", t.elapsed().as_secs_f64());
    println!();
    println!(
        "| clip | colours | budget | strategy | sent kB/s | mean SSIM | mean PSNR dB | 5th pct PSNR | exact frames |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut losses = Vec::new();
    let mut targets = Vec::new();
    for clip in &clips {
        let seconds = clip.seconds();
        for mode in [ColorMode::TrueColor, ColorMode::Palette256] {
            let frames: Vec<Vec<Frame>> = QUANTIZATION_STEPS
                .iter()
                .map(|&q| (0..clip.pictures.len()).map(|k| clip.frame(k, mode, q)).collect())
                .collect();
            for rate in BUDGETS {
                let budget = rate.map_or("unlimited".to_string(), |r| format!("{:.0} kB/s", r / 1000.0));
                let mut rows = Vec::new();
                for (name, strategy) in
                    [("shipped", Strategy::ErrorPerByte), ("changed cells in scan order", Strategy::ScanOrder)]
                {
                    let r = run(clip, &frames[0], mode, rate, Sender::Rate(strategy));
                    assert!(r.max_over_bucket <= 0, "a frame exceeded its bucket by {} bytes", r.max_over_bucket);
                    rows.push(Row::of(name.to_string(), &r, seconds));
                }
                // The whole-frame baseline: the best of its quantization steps by SSIM.
                let whole = QUANTIZATION_STEPS
                    .iter()
                    .zip(&frames)
                    .map(|(&q, frames)| (q, run(clip, frames, mode, rate, Sender::Whole(q))))
                    .map(|(q, r)| Row::of(format!("whole exact frames (step {q})"), &r, seconds))
                    .max_by(|a, b| a.ssim.total_cmp(&b.ssim))
                    .expect("four steps");
                rows.push(whole);
                for row in &rows {
                    println!(
                        "| {} | {} | {budget} | {} | {:.1} | {:.3} | {:.2} | {:.2} | {}/{} |",
                        clip.name,
                        mode.name(),
                        row.label,
                        row.sent_kbps,
                        row.ssim,
                        row.psnr,
                        row.psnr_p5,
                        row.exact.0,
                        row.exact.1
                    );
                }
                // The shipped encoder must be the best at every rate, by both measures.
                let shipped = &rows[0];
                for other in &rows[1..] {
                    if other.ssim > shipped.ssim + 1e-9 || other.psnr > shipped.psnr + 1e-9 {
                        losses.push(format!(
                            "{} {} {budget}: {} {:.3} / {:.2} dB beats the shipped {:.3} / {:.2} dB",
                            clip.name,
                            mode.name(),
                            other.label,
                            other.ssim,
                            other.psnr,
                            shipped.ssim,
                            shipped.psnr
                        ));
                    }
                }
                if clip.name == "pool" && mode == ColorMode::TrueColor {
                    targets.push((rate, shipped.ssim, shipped.sent_kbps));
                }
            }
        }
    }
    println!();
    for (rate, ssim, sent) in targets {
        if rate == Some(250e3) {
            println!("pool at 250 kB/s: SSIM {ssim:.3} (target >= 0.85)");
        } else if rate == Some(50e3) {
            println!("pool at 50 kB/s: SSIM {ssim:.3} (target >= 0.70)");
        } else if rate.is_none() {
            println!("pool, exact frames: {:.2} MB/s (target < 2 MB/s)", sent / 1000.0);
        }
    }
    match losses.is_empty() {
        true => println!("the shipped encoder is the best at every rate, clip and colour mode (SSIM and PSNR)"),
        false => {
            println!("where a baseline beats the shipped encoder:");
            for loss in &losses {
                println!("  {loss}");
            }
        }
    }
    println!("table made in {:.1} s", t.elapsed().as_secs_f64());
}

/// Allocations of the encoder per frame after a warm-up of one pass over the clip.
fn steady_state_allocations(frames: &[Frame]) -> usize {
    let mut encoder = RateEncoder::new();
    let mut shown = Shown::UNKNOWN;
    let mut out = Vec::with_capacity(1 << 20);
    let mut count = 0;
    for pass in 0..2 {
        for frame in frames {
            out.clear();
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            encoder.encode_into(&mut shown, Target::new(frame), 250_000 / 30, RateOptions::default(), &mut out);
            if pass == 1 {
                count += ALLOCATIONS.load(Ordering::Relaxed) - before;
            }
        }
    }
    count
}

fn cpu(c: &mut Criterion) {
    let clip = pool_clip("pool", "pool-160x48.jsonl");
    let frames: Vec<Frame> = (0..clip.pictures.len()).map(|k| clip.frame(k, ColorMode::TrueColor, 1)).collect();
    let allocations = steady_state_allocations(&frames);
    println!("encoder allocations in {} steady-state frames: {allocations}", frames.len());
    assert_eq!(allocations, 0, "the encoder's steady state allocates nothing");
    let mut group = c.benchmark_group("codec/encode_frame_160x48");
    for (name, budget, strategy) in [
        ("rate_100kBps", 100_000 / 30, Strategy::ErrorPerByte),
        ("rate_250kBps", 250_000 / 30, Strategy::ErrorPerByte),
        ("rate_500kBps", 500_000 / 30, Strategy::ErrorPerByte),
        ("rate_2MBps", 2_000_000 / 30, Strategy::ErrorPerByte),
        ("rate_unlimited", UNLIMITED, Strategy::ErrorPerByte),
        ("naive_250kBps", 250_000 / 30, Strategy::ScanOrder),
    ] {
        let mut encoder = RateEncoder::new();
        let mut shown = Shown::UNKNOWN;
        let mut out = Vec::with_capacity(1 << 20);
        let mut n = 0;
        let options = RateOptions { strategy, ..RateOptions::default() };
        group.bench_function(name, |b| {
            b.iter(|| {
                let frame = &frames[n % frames.len()];
                n += 1;
                out.clear();
                encoder.encode_into(&mut shown, Target::new(black_box(frame)), budget, options, &mut out);
                out.len()
            })
        });
    }
    // The whole player's frame: the steps a 30 fps frame covers of the player's pool (gusts,
    // rain, a stone a second), the picture, the cells and the encoder at 250 kB/s.
    let replay =
        tidepool::replay::Replay::read(std::path::Path::new(&fixture("pool-160x48.jsonl"))).expect("the fixture");
    let [w, h] = replay.size();
    let mut scene = replay.spec(tidepool::PoolSettings::default_floor()).build(w, h).expect("a valid size");
    let steps_per_frame = (scene.steps_per_second() / f64::from(FPS)).round().max(1.0) as u64;
    let mut picture = Pixmap::new(w, h).expect("a valid size");
    let mut frame = Frame::new(COLS, ROWS);
    let mut encoder = RateEncoder::new();
    let mut shown = Shown::UNKNOWN;
    let mut out = Vec::with_capacity(1 << 20);
    let mut k = 0u32;
    group.bench_function("player_frame_250kBps", |b| {
        b.iter(|| {
            k += 1;
            if k.is_multiple_of(FPS) {
                let (x, y) = ((k * 53 % w) as i64, (k * 31 % h) as i64);
                scene.apply(&tidepool::Event::Stone(tidepool::Stone::new(x, y, 3, 128).expect("a valid stone")));
            }
            scene.advance(steps_per_frame);
            scene.render(&mut picture);
            frame.draw_pixels(&picture, ColorMode::TrueColor);
            frame.text(0, ROWS - 1, " pool \u{b7} 30 fps", Color::Index(15), Color::Index(4));
            out.clear();
            encoder.encode_into(&mut shown, Target::new(&frame), 250_000 / 30, RateOptions::default(), &mut out);
            out.len()
        })
    });
    // Today's encoder on the same frames, as the baseline of the same run.
    let mut shown = Shown::UNKNOWN;
    let mut out = Vec::with_capacity(1 << 20);
    let mut n = 0;
    group.bench_function("today_diff_unlimited", |b| {
        b.iter(|| {
            let frame = &frames[n % frames.len()];
            n += 1;
            out.clear();
            tidepool::testing::encode_into(&mut shown, black_box(frame), EncodeOptions::default(), &mut out);
            out.len()
        })
    });
    group.finish();
}

/// How far a screen falls behind when it shows the true frame k frames late (what a link too
/// slow for any approximation would give).
fn stale() {
    let clip = pool_clip("pool", "pool-160x48.jsonl");
    let (w, h) = (PICTURE.0 as usize, PICTURE.1 as usize);
    for k in [1usize, 2, 5, 10, 20, 40] {
        let (mut psnr, mut ssim, mut n) = (0.0, 0.0, 0);
        for i in (60 + k)..clip.pictures.len() {
            let mut screen = TerminalModel::new(COLS, ROWS);
            screen.lf_returns = false;
            let frame = clip.frame(i - k, ColorMode::TrueColor, 1);
            let (bytes, _) = tidepool::testing::encode(&Shown::UNKNOWN, &frame, EncodeOptions::default());
            screen.feed(&bytes);
            psnr += quality::measure(&screen, &clip.pictures[i]).psnr();
            ssim += clip.references[i].ssim(&quality::screen_luma(&screen, w, h));
            n += 1;
        }
        println!("stale by {k} frames: {:.2} dB, SSIM {:.3}", psnr / n as f64, ssim / n as f64);
    }
}

/// The shipped encoder (and with `CODEC_SERIES=1` the scan-order baseline beside it) on the
/// pool clip, or the clips `CODEC_CLIPS` names, in truecolor (`CODEC_MODE=256`: 256 colours),
/// for trying changes.
fn quick() {
    let mode = match std::env::var("CODEC_MODE").as_deref() {
        Ok("256") => ColorMode::Palette256,
        _ => ColorMode::TrueColor,
    };
    let series = std::env::var_os("CODEC_SERIES").is_some();
    let clips = match std::env::var_os("CODEC_CLIPS") {
        Some(_) => clips(),
        None => vec![pool_clip("pool", "pool-160x48.jsonl")],
    };
    for clip in &clips {
        println!("{} in {}:", clip.name, mode.name());
        let frames: Vec<Frame> = (0..clip.pictures.len()).map(|k| clip.frame(k, mode, 1)).collect();
        for rate in [Some(25e3), Some(50e3), Some(100e3), Some(250e3), Some(500e3), Some(2e6), None] {
            let t = Instant::now();
            let r = run(clip, &frames, mode, rate, Sender::Rate(Strategy::ErrorPerByte));
            println!(
                "{:>9}: sent {:.1} kB/s, SSIM {:.3}, PSNR {:.2} dB, 5th pct {:.2} ({:.1} s)",
                rate.map_or("unlimited".into(), |r| format!("{:.0} kB/s", r / 1e3)),
                r.bytes as f64 / clip.seconds() / 1000.0,
                Run::mean(&r.ssim),
                Run::mean(&r.psnr),
                percentile(&r.psnr, 0.05),
                t.elapsed().as_secs_f64()
            );
            if series {
                let by_second = |r: &Run| -> String {
                    r.ssim.chunks(FPS as usize).map(|s| format!("{:.2}", Run::mean(s))).collect::<Vec<_>>().join(" ")
                };
                println!("           SSIM second by second: {}", by_second(&r));
                let scan = run(clip, &frames, mode, rate, Sender::Rate(Strategy::ScanOrder));
                println!("           scan order ({:.3}):       {}", Run::mean(&scan.ssim), by_second(&scan));
            }
        }
    }
}

fn main() {
    let only = std::env::var("CODEC").unwrap_or_default();
    if only == "quick" {
        quick();
        return;
    }
    if only == "stale" {
        stale();
        return;
    }
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
