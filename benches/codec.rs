//! The terminal encoder measured like a codec (issue 14 §5).
//!
//! The fixture: `tests/fixtures/alive-160x48.jsonl`, about 12 s of the alive pool recorded by
//! the player in a 160x48 terminal (160x94 pixels and a status line) with its defaults (the
//! breeze, rain, damping 6) and a stone about every second, re-simulated exactly. The player's
//! 30 fps means one frame every two steps.
//!
//! For each budget (50, 100, 250 and 500 kB/s, and unlimited) the rate-controlled encoder
//! ([`tidepool::terminal::RateEncoder`]) and the naive strategy (changed cells in screen order until the
//! budget runs out, the same encoder with [`Strategy::ScanOrder`]) encode every frame with a
//! [`ByteBucket`] at that rate on a simulated 30 fps clock; every emitted frame is fed to the
//! terminal model ([`tidepool::terminal::TerminalModel`], exactly 160x48, no spare row) and the screen is
//! compared with the true frame: bytes/s, mean and 5th-percentile PSNR (8-bit sRGB, both
//! halves of every picture cell, the status row left out, an exact frame counted as 99 dB) and
//! the mean OKLab distance per pixel. The unlimited rows also check that every frame is exact
//! and compare the bytes with today's encoder (`tidepool::terminal::encode_into`) on the same frames.
//!
//! Then criterion measures the encoder's CPU per frame at 160x48 on the same frames.
//!
//!     cargo bench --bench codec                # the table, then the CPU figures
//!     CODEC=table cargo bench --bench codec    # the table only (about a minute)
//!     CODEC=cpu cargo bench --bench codec      # the CPU figures only
//!     CODEC=stale cargo bench --bench codec    # PSNR of the true frame k frames late
//!     CODEC=quick cargo bench --bench codec    # the rate-controlled rows alone, for tuning

use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use criterion::Criterion;
use tidepool::Script;
use tidepool::terminal::{
    self as quality, ByteBucket, Color, ColorMode, EncodeOptions, Frame, RateEncoder, RateOptions, Shown, Strategy,
    Target, TerminalModel, UNLIMITED,
};
use tiny_skia::Pixmap;

/// The fixture replay.
const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/alive-160x48.jsonl");

const COLS: usize = 160;
const ROWS: usize = 48;
const STEPS_PER_FRAME: u64 = 2;
const FPS: u32 = 30;
/// Budgets in bytes per second; `None` is unlimited.
const BUDGETS: [Option<f64>; 5] = [Some(50e3), Some(100e3), Some(250e3), Some(500e3), None];

/// The strategies compared: (name, order, approximations allowed).
const STRATEGIES: [(&str, Strategy, bool); 3] = [
    ("rate-controlled", Strategy::ErrorPerByte, true),
    ("rate-controlled, exact cells only", Strategy::ErrorPerByte, false),
    ("naive scan order", Strategy::ScanOrder, false),
];

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

/// One frame of the fixture: the cells the player would send and the true picture.
struct Shot {
    frame: Frame,
    picture: Pixmap,
}

/// The fixture, frame by frame, in `mode`: the replay re-simulated, a frame every two steps,
/// with a status line as the player draws one.
fn fixture(mode: ColorMode) -> Vec<Shot> {
    let replay = tidepool::replay::read(std::path::Path::new(FIXTURE)).expect("the committed fixture replay");
    assert_eq!(replay.header.size, [COLS as u32, 2 * (ROWS as u32 - 1)], "a 160x48-cell recording");
    let spec = replay.spec(tidepool::pool_floor());
    let [w, h] = replay.header.size;
    let mut scene = spec.build(w, h).expect("a valid size");
    let events = replay.script();
    let mut script = Script::new(&events);
    let mut shots = Vec::new();
    let mut step = 0;
    while step + STEPS_PER_FRAME <= replay.end_step() {
        step += STEPS_PER_FRAME;
        script.run_to(scene.as_mut(), step);
        let picture = scene.snapshot().expect("a valid size");
        let mut frame = Frame::new(COLS, ROWS);
        frame.draw_pixels(&picture, mode);
        let seconds = step as f64 / 60.0;
        let status = format!(" pool \u{b7} rain 0.05 \u{b7} breeze 1 \u{b7} damping 6 \u{b7} {seconds:.1} s");
        frame.clear_row(ROWS - 1, Color::Index(4));
        frame.text(0, ROWS - 1, &status, Color::Index(15), Color::Index(4));
        shots.push(Shot { frame, picture });
    }
    shots
}

/// The numbers of one run.
struct Run {
    bytes: usize,
    psnr: Vec<f64>,
    oklab: f64,
    exact_frames: usize,
    max_over_bucket: isize,
}

fn run(shots: &[Shot], mode: ColorMode, rate: Option<f64>, strategy: Strategy, approximate: bool) -> Run {
    let start = Instant::now();
    let mut bucket = rate.map_or_else(ByteBucket::unlimited, ByteBucket::new);
    bucket.refill(start);
    let mut encoder = RateEncoder::new();
    let mut shown = Shown::UNKNOWN;
    let mut screen = TerminalModel::new(COLS, ROWS);
    screen.lf_returns = false;
    let options = RateOptions { strategy, approximate, ..RateOptions::default() };
    let mut out = Vec::new();
    let mut result = Run { bytes: 0, psnr: Vec::new(), oklab: 0.0, exact_frames: 0, max_over_bucket: isize::MIN };
    for (n, shot) in shots.iter().enumerate() {
        // The first frame at t = 0 finds an empty bucket: give it one frame's worth.
        bucket.refill(start + Duration::from_secs_f64((n + 1) as f64 / f64::from(FPS)));
        let budget = bucket.budget();
        out.clear();
        let target = if mode == ColorMode::TrueColor {
            Target::new(&shot.frame)
        } else {
            Target::with_truth(&shot.frame, &shot.picture, mode)
        };
        encoder.encode_into(&mut shown, target, budget, options, &mut out);
        bucket.spend(out.len());
        if budget != UNLIMITED {
            result.max_over_bucket = result.max_over_bucket.max(out.len() as isize - budget as isize);
        }
        result.bytes += out.len();
        screen.feed(&out);
        let q = quality::measure(&screen, &shot.picture);
        result.psnr.push(q.psnr());
        result.oklab += q.oklab;
        result.exact_frames += usize::from(q.mse == 0.0);
    }
    result.oklab /= shots.len() as f64;
    result
}

/// Today's encoder on the same frames: its total bytes.
fn today(shots: &[Shot]) -> usize {
    let mut shown = Shown::UNKNOWN;
    let mut out = Vec::new();
    let mut total = 0;
    for shot in shots {
        out.clear();
        tidepool::terminal::encode_into(&mut shown, &shot.frame, EncodeOptions::default(), &mut out);
        total += out.len();
    }
    total
}

fn percentile(values: &[f64], p: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn table() {
    let t = Instant::now();
    let shots = fixture(ColorMode::TrueColor);
    let seconds = shots.len() as f64 / f64::from(FPS);
    println!(
        "codec fixture: {} frames of {COLS}x{ROWS} cells ({seconds:.0} s at {FPS} fps of {FIXTURE}), made in {:.1} s",
        shots.len(),
        t.elapsed().as_secs_f64()
    );
    println!();
    println!("| budget | strategy | sent kB/s | mean PSNR dB | 5th pct PSNR dB | mean ΔE_OK | exact frames |");
    println!("|---|---|---|---|---|---|---|");
    let mut gains = Vec::new();
    for rate in BUDGETS {
        let label = rate.map_or("unlimited".to_string(), |r| format!("{:.0} kB/s", r / 1000.0));
        let mut means = Vec::new();
        for (name, strategy, approximate) in STRATEGIES {
            if rate.is_none() && !approximate && strategy == Strategy::ErrorPerByte {
                continue; // the same as the row above: unlimited draws every cell exactly
            }
            let r = run(&shots, ColorMode::TrueColor, rate, strategy, approximate);
            assert!(r.max_over_bucket <= 0, "a frame exceeded its bucket by {} bytes", r.max_over_bucket);
            let mean = r.psnr.iter().sum::<f64>() / r.psnr.len() as f64;
            println!(
                "| {label} | {name} | {:.1} | {mean:.2} | {:.2} | {:.4} | {}/{} |",
                r.bytes as f64 / seconds / 1000.0,
                percentile(&r.psnr, 0.05),
                r.oklab,
                r.exact_frames,
                r.psnr.len()
            );
            means.push(mean);
            if rate.is_none() && strategy == Strategy::ErrorPerByte {
                let old = today(&shots);
                assert_eq!(r.exact_frames, shots.len(), "unlimited is exact");
                println!(
                    "|  | today's diff encoder | {:.1} | exact | exact | 0 | {}/{} |",
                    old as f64 / seconds / 1000.0,
                    shots.len(),
                    shots.len()
                );
                assert!(r.bytes <= old, "unlimited sent {} bytes, today's encoder {old}", r.bytes);
                gains.push(format!(
                    "unlimited: {} bytes vs today's {old} ({:+.2}%)",
                    r.bytes,
                    100.0 * (r.bytes as f64 / old as f64 - 1.0)
                ));
            }
        }
        if rate.is_some() {
            gains.push(format!(
                "{label}: {:+.2} dB over naive ({:+.2} dB from the approximations)",
                means[0] - means[2],
                means[0] - means[1]
            ));
        }
    }
    println!();
    for g in gains {
        println!("{g}");
    }
    // The palette modes: same rate control, errors against the true colours.
    println!();
    println!(
        "| colours @ 100 kB/s | strategy | sent kB/s | mean PSNR dB | 5th pct PSNR dB | mean ΔE_OK | exact frames |"
    );
    println!("|---|---|---|---|---|---|---|");
    for mode in [ColorMode::Palette256, ColorMode::Palette16] {
        let shots = fixture(mode);
        for (name, strategy, approximate) in STRATEGIES {
            let r = run(&shots, mode, Some(100e3), strategy, approximate);
            let mean = r.psnr.iter().sum::<f64>() / r.psnr.len() as f64;
            println!(
                "| {} | {name} | {:.1} | {mean:.2} | {:.2} | {:.4} | {}/{} |",
                mode.name(),
                r.bytes as f64 / seconds / 1000.0,
                percentile(&r.psnr, 0.05),
                r.oklab,
                r.exact_frames,
                r.psnr.len()
            );
        }
    }
    println!();
    println!("table made in {:.1} s", t.elapsed().as_secs_f64());
}

/// Allocations of the encoder per frame after a warm-up of one pass over the fixture.
fn steady_state_allocations(shots: &[Shot]) -> usize {
    let mut encoder = RateEncoder::new();
    let mut shown = Shown::UNKNOWN;
    let mut out = Vec::with_capacity(1 << 20);
    let mut count = 0;
    for pass in 0..2 {
        for shot in shots {
            out.clear();
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            encoder.encode_into(&mut shown, Target::new(&shot.frame), 250_000 / 30, RateOptions::default(), &mut out);
            if pass == 1 {
                count += ALLOCATIONS.load(Ordering::Relaxed) - before;
            }
        }
    }
    count
}

fn cpu(c: &mut Criterion) {
    let shots = fixture(ColorMode::TrueColor);
    let allocations = steady_state_allocations(&shots);
    println!("encoder allocations in {} steady-state frames: {allocations}", shots.len());
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
                let shot = &shots[n % shots.len()];
                n += 1;
                out.clear();
                encoder.encode_into(&mut shown, Target::new(black_box(&shot.frame)), budget, options, &mut out);
                out.len()
            })
        });
    }
    // The whole player's frame: two steps of the alive pool (breeze, rain, a stone a second),
    // the picture, the cells and the encoder at 250 kB/s.
    let replay = tidepool::replay::read(std::path::Path::new(FIXTURE)).expect("the committed fixture replay");
    let [w, h] = replay.header.size;
    let mut scene = replay.spec(tidepool::pool_floor()).build(w, h).expect("a valid size");
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
            scene.advance(STEPS_PER_FRAME);
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
            let shot = &shots[n % shots.len()];
            n += 1;
            out.clear();
            tidepool::terminal::encode_into(&mut shown, black_box(&shot.frame), EncodeOptions::default(), &mut out);
            out.len()
        })
    });
    group.finish();
}

fn stale() {
    let shots = fixture(ColorMode::TrueColor);
    for k in [1usize, 2, 5, 10, 20, 40] {
        let mut psnr = 0.0;
        let mut n = 0;
        for i in (60 + k)..shots.len() {
            let mut screen = TerminalModel::new(COLS, ROWS);
            screen.lf_returns = false;
            let (bytes, _) = tidepool::terminal::encode(&Shown::UNKNOWN, &shots[i - k].frame, EncodeOptions::default());
            screen.feed(&bytes);
            psnr += quality::measure(&screen, &shots[i].picture).psnr();
            n += 1;
        }
        println!("stale by {k} frames: {:.2} dB", psnr / n as f64);
    }
}

/// A short table of the rate-controlled encoder alone, for trying changes.
fn quick() {
    let shots = fixture(ColorMode::TrueColor);
    let seconds = shots.len() as f64 / f64::from(FPS);
    for rate in [50e3, 100e3, 250e3, 500e3, 2e6] {
        let t = Instant::now();
        let r = run(&shots, ColorMode::TrueColor, Some(rate), Strategy::ErrorPerByte, true);
        let mean = r.psnr.iter().sum::<f64>() / r.psnr.len() as f64;
        println!(
            "{:>5.0} kB/s: sent {:.1} kB/s, mean PSNR {mean:.2} dB, 5th pct {:.2}, ΔE {:.4} ({:.1} s)",
            rate / 1e3,
            r.bytes as f64 / seconds / 1000.0,
            percentile(&r.psnr, 0.05),
            r.oklab,
            t.elapsed().as_secs_f64()
        );
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
