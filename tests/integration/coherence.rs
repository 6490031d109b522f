//! The coherence table of issue 21: does the water move like water filmed at 30 fps, or boil?
//!
//! Each scene is rendered as the player shows it in a 160x48 terminal (160x94 pixels, 30 fps,
//! the player's defaults) by the command a user types (`tidepool render ... --frames 300 --fps
//! 30` into PNG files), and the frames are compared by their luma:
//! - SSIM (`tidepool::testing::ssim`: Gaussian window of 1.5, the usual constants) between
//!   frames 1, 3 and 30 apart (33 ms, 100 ms, 1 s), averaged over every such pair;
//! - alive: the share of pixels whose luma differs by at least 2 % of full scale (5.1 of 255)
//!   between frames a second apart, averaged over every such pair.
//!
//! Water filmed at 30 fps: consecutive frames alike (SSIM >= 0.90) while the water is alive
//! (>= 40 % of pixels move within a second).
//!
//!     cargo build --release && cargo test --release --test integration coherence -- --ignored --nocapture
//!
//! The pool's rows replay the committed sessions: `alive-160x48.jsonl` was recorded before
//! the gusts and the finer grid (its header has neither, so it replays the old pool bit for
//! bit: the "before" row), `pool-160x48.jsonl` and `pool-stones-160x48.jsonl` with today's
//! defaults (`scripts/record_pool_fixtures.sh`).

use std::path::Path;

use tidepool::testing::{Luma, ssim};

use crate::common::{run, scratch, stderr};

/// The frame rate measured, and the frames a second apart.
const FPS: usize = 30;
/// A pixel is alive when its luma moves by at least this much in a second (2 % of 255).
const ALIVE_LUMA: f32 = 0.02 * 255.0;

/// A row of the guide's table ("Water filmed at 30 fps"), in the order of `coherence_table`.
#[derive(Clone, Copy, Debug)]
struct Quoted {
    ssim: [f64; 3],
    alive_percent: f64,
}

const QUOTED: [Quoted; 6] = [
    Quoted { ssim: [0.515, 0.252, 0.333], alive_percent: 80.1 },
    Quoted { ssim: [0.975, 0.897, 0.792], alive_percent: 47.7 },
    Quoted { ssim: [0.962, 0.844, 0.707], alive_percent: 51.2 },
    Quoted { ssim: [0.996, 0.986, 0.777], alive_percent: 32.9 },
    Quoted { ssim: [0.994, 0.981, 0.762], alive_percent: 35.1 },
    Quoted { ssim: [1.000, 0.999, 0.983], alive_percent: 4.4 },
];

/// One row of the table.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Coherence {
    /// Mean SSIM of frames 1, 3 and 30 apart.
    ssim: [f64; 3],
    /// The mean share of pixels alive within a second.
    alive: f64,
}

/// SSIM at 33 ms, 100 ms and 1 s, and the alive share, of frames shown `FPS` a second.
fn coherence(frames: &[Luma]) -> Coherence {
    let lag = |k: usize| {
        let pairs = frames.len().saturating_sub(k).max(1);
        frames.windows(k + 1).map(|w| ssim(&w[0], &w[k])).sum::<f64>() / pairs as f64
    };
    let moved = |a: &Luma, b: &Luma| {
        let (w, h) = (a.width(), a.height());
        let alive = (0..h).flat_map(|y| (0..w).map(move |x| (x, y)));
        let count = alive.filter(|&(x, y)| (a.get(x, y) - b.get(x, y)).abs() >= ALIVE_LUMA).count();
        count as f64 / (w * h).max(1) as f64
    };
    let pairs = frames.len().saturating_sub(FPS).max(1);
    let alive = frames.windows(FPS + 1).map(|w| moved(&w[0], &w[FPS])).sum::<f64>() / pairs as f64;
    Coherence { ssim: [lag(1), lag(3), lag(FPS)], alive }
}

/// The PNG frames of a `{frame:04}` sequence in `dir`, in order.
fn read_frames(dir: &Path) -> Vec<Luma> {
    let mut names: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    names.retain(|p| p.extension().is_some_and(|e| e == "png"));
    names.sort();
    names.iter().map(|p| Luma::of_pixmap(&tidepool::testing::load_image(p).unwrap())).collect()
}

/// Renders 300 frames at 30 fps with `args` (a `render` command without its output) and
/// measures them.
fn measure(name: &str, args: &[&str]) -> Coherence {
    let dir = scratch(&format!("coherence-{name}"));
    let pattern = dir.join("f_{frame:04}.png");
    let mut all: Vec<&str> = args.to_vec();
    let pattern = pattern.to_str().unwrap();
    all.extend(["--frames", "300", "--fps", "30", "--out", pattern]);
    let output = run(&all);
    assert!(output.status.success(), "tidepool {}: {}", all.join(" "), stderr(&output));
    let frames = read_frames(&dir);
    assert_eq!(frames.len(), 300, "{name}");
    assert_eq!((frames[0].width(), frames[0].height()), (160, 94), "{name}: a 160x48 terminal's picture");
    coherence(&frames)
}

#[test]
fn identical_frames_are_coherent_and_still_and_noise_is_neither() {
    let still: Vec<Luma> = (0..40).map(|_| Luma::from_fn(16, 12, |x, y| [(x * 9) as u8, (y * 17) as u8, 90])).collect();
    let c = coherence(&still);
    assert!(c.ssim.iter().all(|&s| (s - 1.0).abs() < 1e-9) && c.alive == 0.0, "{c:?}");
    let mut seed = 7u32;
    let mut noise = || {
        seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
        (seed >> 16) as u8
    };
    let boiling: Vec<Luma> = (0..40).map(|_| Luma::from_fn(16, 12, |_, _| [noise(), noise(), noise()])).collect();
    let c = coherence(&boiling);
    assert!(c.ssim.iter().all(|&s| s < 0.2) && c.alive > 0.9, "{c:?}");
}

#[test]
#[ignore = "a measurement: renders 1,800 frames (about a minute in release)"]
fn coherence_table() {
    let fixture = |name: &str| format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    let (before, after, stones) =
        (fixture("alive-160x48.jsonl"), fixture("pool-160x48.jsonl"), fixture("pool-stones-160x48.jsonl"));
    let small = ["--size", "160x94", "--ssaa", "1"];
    let rows: Vec<(&str, Vec<&str>)> = vec![
        ("pool, player defaults, before (alive-160x48.jsonl)", vec!["render", "pool", "--replay", &before]),
        ("pool, player defaults (pool-160x48.jsonl)", vec!["render", "pool", "--replay", &after]),
        ("pool, a stone every 0.5 s (pool-stones-160x48.jsonl)", vec!["render", "pool", "--replay", &stones]),
        ("ocean, player defaults (10 m/s)", [&["render", "ocean"][..], &small].concat()),
        ("ocean, Beaufort 6", [&["render", "ocean", "--beaufort", "6"][..], &small].concat()),
        ("lake, player defaults (3 m/s)", [&["render", "lake"][..], &small].concat()),
    ];
    println!("| scene | SSIM 33 ms | 100 ms | 1 s | alive in 1 s |");
    println!("|---|---|---|---|---|");
    let mut results = Vec::new();
    for (k, (name, args)) in rows.iter().enumerate() {
        let c = measure(&format!("row{k}"), args);
        println!("| {name} | {:.3} | {:.3} | {:.3} | {:.1} % |", c.ssim[0], c.ssim[1], c.ssim[2], 100.0 * c.alive);
        results.push(c);
    }
    // The guide's table, row for row: the frames are the same bytes on any machine, so the
    // figures are too, to the digits printed (half a unit of the last digit, and a little
    // for the sums' rounding).
    for ((c, (name, _)), quoted) in results.iter().zip(&rows).zip(QUOTED) {
        let close = c.ssim.iter().zip(quoted.ssim).all(|(a, b)| (a - b).abs() <= 0.0006)
            && (100.0 * c.alive - quoted.alive_percent).abs() <= 0.06;
        assert!(close, "{name}: measured {c:?}, the guide says {quoted:?}");
    }
    // The targets of issue 21 for the player's scenes (the "before" row is the old pool).
    for (c, (name, _)) in results.iter().zip(&rows).skip(1) {
        assert!(c.ssim[0] >= 0.90, "{name}: consecutive frames SSIM {:.3} < 0.90", c.ssim[0]);
    }
    let pool = results[1];
    assert!(pool.alive >= 0.40, "the default pool is alive in {:.1} % of its pixels < 40 %", 100.0 * pool.alive);
}
