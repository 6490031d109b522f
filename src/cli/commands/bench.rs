//! `tidepool bench`: how fast this machine runs tidepool, stage by stage, in a few seconds —
//! the way a user checks whether a small VPS can run the interactive scenes.
//!
//! Every figure says what it measures. The pool's simulation is timed both ways it runs: one
//! step at a time (what the player does, 60 steps a second) and 16 steps in one blocked sweep
//! (what `render` does for long runs), each against the papers' plain loop in the same run. The
//! verdict is the player's own frame path for every scene: the steps of one frame at 30 fps,
//! the picture, the cells with the status line, and the diff encoding against the frame before.

use std::hint::black_box;
use std::time::{Duration, Instant};

use crate::Action;
use crate::encode::{halfblock, png};
use crate::output::graphics::geometry::{Layout, layout};
use crate::play::GraphicsMode;
use crate::play::{Bandwidth, GraphicsRequest, Host, HostConfig, Player, Request, Screen, ScreenConfig};
use crate::play::{ColorMode, EncodeOptions};
use crate::sim::ripple::RipplePool;
use crate::simd::Simd;
use crate::{Damping, LakeSettings, OceanSettings, OceanView, PoolSettings, SceneSpec, Stone};
use tiny_skia::Pixmap;

use crate::cli::args::BenchArgs;
use crate::cli::error::Result;

/// One measured workload.
struct Row {
    stage: String,
    size: String,
    median: Duration,
    rate: String,
}

/// The player's frame rate the verdict is about.
const PLAYER_FPS: f64 = 30.0;

/// Runs `work` repeatedly for about `budget` (at least 3 times) and returns the median time.
fn median_time(budget: Duration, mut work: impl FnMut()) -> Duration {
    work(); // warm-up: caches, scratch buffers, thread pool
    let mut times = Vec::new();
    let started = Instant::now();
    while times.len() < 3 || (started.elapsed() < budget && times.len() < 1000) {
        let t = Instant::now();
        work();
        times.push(t.elapsed());
    }
    times.sort();
    times[times.len() / 2]
}

fn rough_pool(w: usize, h: usize) -> RipplePool {
    let mut pool = RipplePool::new(w, h, Damping::PAPERS);
    for k in 0..48 {
        pool.drop_stone(Stone::clamped((k * 7919 % w) as i32, (k * 104729 % h) as i32, 5, 160));
    }
    pool.advance(10);
    pool
}

/// The papers' loop, transliterated (the baseline every simulation figure is compared with).
fn papers_step(current: &mut Vec<i16>, previous: &mut Vec<i16>, w: usize, h: usize) {
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            let sum = i32::from(current[i - 1])
                + i32::from(current[i + 1])
                + i32::from(current[i - w])
                + i32::from(current[i + w]);
            let mut v = (sum >> 1) - i32::from(previous[i]);
            v -= v >> 5;
            previous[i] = v as i16;
        }
    }
    std::mem::swap(current, previous);
}

/// The scenes at their defaults as the player shows them (no supersampling; the pool with its
/// grid, pace and gusts), and with `ssaa` for pictures (the pool as `render` draws it).
fn scenes(ssaa: u32) -> [(&'static str, SceneSpec); 3] {
    let mut pool = PoolSettings { rain_rate: 0.3, ..PoolSettings::default() };
    if ssaa == 1 {
        let player = crate::cli::args::PoolDefaults::PLAYER;
        pool = PoolSettings {
            breeze: player.breeze,
            breeze_style: player.breeze_style,
            grid: player.grid,
            steps_per_second: player.steps_per_second,
            ..pool
        };
    }
    let ocean = OceanSettings { view: OceanView { ssaa, ..OceanView::default() }, ..OceanSettings::default() };
    let lake = LakeSettings { ssaa, ..LakeSettings::default() };
    [("pool", SceneSpec::Pool(pool)), ("ocean", SceneSpec::Ocean(ocean)), ("lake", SceneSpec::Lake(lake))]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Runs `tidepool bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    let budget = Duration::from_secs_f64(args.seconds.max(0.05));
    let threads = rayon::current_num_threads();
    println!(
        "tidepool bench: {threads} threads, SIMD kernel {}, {:.1} s per workload",
        Simd::detect(),
        budget.as_secs_f64()
    );
    let mut rows = simulation_rows(budget, threads);
    let terminal = (args.terminal.width() as u16, (args.terminal.height() / 2 + 1) as u16);
    let verdicts = player_rows(budget, terminal, &mut rows);
    let Some(text) = text_row(budget, terminal)? else { return Ok(()) };
    rows.push(text);
    picture_rows(budget, &mut rows);
    print(&rows, terminal, &verdicts);
    Ok(())
}

/// The simulation: the papers' loop, then tidepool one step at a time and blocked, on one
/// thread and on `threads`.
fn simulation_rows(budget: Duration, threads: usize) -> Vec<Row> {
    let mut rows = Vec::new();
    let side = 1024usize;
    let cells = (side * side) as f64;
    let start = rough_pool(side, side);
    let (mut current, mut previous) = (start.heights().to_vec(), start.previous_heights().to_vec());
    let papers = median_time(budget, || papers_step(&mut current, &mut previous, side, side));
    let rate = |median: Duration, steps: f64| cells * steps / median.as_secs_f64() / 1e9;
    let base = rate(papers, 1.0);
    rows.push(Row {
        stage: "pool simulation, the papers' loop".into(),
        size: format!("{side}x{side}"),
        median: papers,
        rate: format!("{base:.2} G cell-updates/s"),
    });
    for (threads, steps, label) in [
        (1, 1, "one step (the player)"),
        (1, 16, "16 steps blocked (render)"),
        (threads, 16, "16 steps blocked (render)"),
    ] {
        let Some(pool) = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok() else { continue };
        let mut water = start.clone();
        let median = pool.install(|| median_time(budget, || water.advance(steps)));
        let r = rate(median, steps as f64);
        rows.push(Row {
            stage: format!("pool simulation, {label}, {threads} thread{}", if threads == 1 { "" } else { "s" }),
            size: format!("{side}x{side}"),
            median: median / steps as u32,
            rate: format!("{r:.2} G cell-updates/s ({:.1}x the papers' loop)", r / base),
        });
    }
    rows
}

/// The player's frame for every scene, at the terminal size: the play session's own host,
/// seat and screen, on a made-up clock of 30 frames a second (every frame is drawn). Returns
/// each scene's median frame and its share of a core at 30 fps.
fn player_rows(
    budget: Duration,
    (cols, rows_cells): (u16, u16),
    rows: &mut Vec<Row>,
) -> Vec<(&'static str, Duration, f64)> {
    let mut verdicts = Vec::new();
    for (name, spec) in scenes(1) {
        let t0 = Instant::now();
        let config = ScreenConfig {
            fps: PLAYER_FPS as u32,
            bandwidth: Bandwidth::Unlimited,
            color: ColorMode::TrueColor,
            color_auto: false,
            colour_hint: false,
            encode: EncodeOptions::default(),
            graphics: GraphicsRequest::Force(crate::play::GraphicsMode::Cells),
            probe: None,
            link_path: crate::play::LinkPath::Direct,
        };
        let screen = Screen::new(config, (cols, rows_cells), t0);
        let host_config = HostConfig { scenes: vec![spec], seed: 1, record: None, screenshots: false };
        let Ok(mut host) = Host::new(host_config, screen.picture_size(), t0) else { continue };
        let mut player = Player::new(screen, host.size(), None);
        let (w, h) = host.size();
        let mut picture = Pixmap::new(w, h).expect("a terminal-sized picture");
        let mut bytes = Vec::new();
        let mut k = 0u32;
        let mut sent = 0usize;
        let median = median_time(budget, || {
            k = k.wrapping_add(1);
            let now = t0 + Duration::from_secs_f64(f64::from(k) / PLAYER_FPS);
            if k.is_multiple_of(30) {
                // A stone a second, as a player drops them.
                let (x, y) = ((k * 7919 % w) as i32, (k * 104729 % h) as i32);
                host.apply(Request::Act(Action::Stone { x, y, radius: 3, big: false }), now);
            }
            host.advance(now);
            host.render(&mut picture);
            bytes.clear();
            sent = player.frame(now, &picture, host.status(), &mut bytes);
        });
        black_box(sent);
        let core = median.as_secs_f64() * PLAYER_FPS * 100.0;
        rows.push(Row {
            stage: format!("player frame, {name}: 1/30 s of steps, picture, cells, diff"),
            size: format!("{cols}x{rows_cells} cells"),
            median,
            rate: format!("{:.0} fps; {core:.1} % of a core at 30 fps", 1.0 / median.as_secs_f64()),
        });
        verdicts.push((name, median, core));
    }
    verdicts
}

/// A whole frame of half-block text, for a resize or a first frame (`None` when the
/// terminal's pool cannot be made).
fn text_row(budget: Duration, (cols, rows_cells): (u16, u16)) -> Result<Option<Row>> {
    // The half-block picture above the status line, as the cells layout sizes it.
    let (w, h) = layout(GraphicsMode::Cells, (cols, rows_cells), None, None, Layout::SCALED_CAP).picture;
    let Ok(mut pool) = scenes(1)[0].1.build(w, h) else { return Ok(None) };
    pool.advance(30);
    let frame = pool.snapshot()?;
    let text_median = median_time(budget, || {
        black_box(halfblock(black_box(&frame)));
    });
    Ok(Some(Row {
        stage: "half-block text, a whole frame".into(),
        size: format!("{w}x{h}"),
        median: text_median,
        rate: crate::output::units::human_bytes(halfblock(&frame).len() as u64),
    }))
}

/// Pictures at full HD (the ocean and the lake at 2x2 supersampling, as `render` does), and
/// the PNG encoding of the pool's.
fn picture_rows(budget: Duration, rows: &mut Vec<Row>) {
    for (name, spec) in scenes(2) {
        let Ok(mut scene) = spec.build(1920, 1080) else { continue };
        let mut picture = Pixmap::new(1920, 1080).expect("a full-HD picture");
        let median = median_time(budget, || {
            scene.advance(1);
            scene.render(&mut picture);
        });
        let ssaa = if name == "pool" { "" } else { ", ssaa 2" };
        rows.push(Row {
            stage: format!("{name} picture{ssaa}: a step and the picture"),
            size: "1920x1080".into(),
            median,
            rate: format!("{:.0} fps", 1.0 / median.as_secs_f64()),
        });
        if name == "pool" {
            let png_median = median_time(budget, || {
                black_box(png(black_box(&picture)));
            });
            rows.push(Row {
                stage: "PNG encode".into(),
                size: "1920x1080".into(),
                median: png_median,
                rate: crate::output::units::human_bytes(png(&picture).len() as u64),
            });
        }
    }
}

/// The table, then the verdict for the player in this terminal.
fn print(rows: &[Row], (cols, rows_cells): (u16, u16), verdicts: &[(&str, Duration, f64)]) {
    println!("{:<58} {:>16} {:>11}   rate", "stage", "size", "median");
    for row in rows {
        println!("{:<58} {:>16} {:>8.3} ms   {}", row.stage, row.size, ms(row.median), row.rate);
    }
    println!("\nthe player in a {cols}x{rows_cells}-cell terminal (frames at 30 fps, simulation in real time):");
    for &(name, median, core) in verdicts {
        let fits = if ms(median) < 1000.0 / 60.0 { "60 fps would fit" } else { "60 fps would not fit" };
        println!("  {name:<6} {:>7.2} ms a frame, {core:>5.1} % of one core at 30 fps; {fits}", ms(median));
    }
}
