//! `tidepool bench`: how fast this machine runs tidepool, stage by stage, in a few seconds —
//! the way a user checks whether a small VPS can run the interactive pool at 60 fps.

use std::hint::black_box;
use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use tidepool::encode::{halfblock, png};
use tidepool::{Damping, LakeSettings, OceanSettings, OceanView, PoolScene, PoolSettings, RipplePool, SceneSpec};
use tidepool::{Simd, Stone};

use crate::cli::BenchArgs;
use crate::error::Result;

/// One measured workload.
struct Row {
    stage: String,
    size: String,
    median: Duration,
    rate: String,
}

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

/// The scenes besides the pool, at their defaults, drawing `w x h` with `ssaa` supersampling.
fn other_scenes(w: u32, h: u32, ssaa: u32) -> Vec<(&'static str, Box<dyn tidepool::Playable>)> {
    let ocean = OceanSettings { view: OceanView { ssaa, ..OceanView::default() }, ..OceanSettings::default() };
    let lake = LakeSettings { ssaa, ..LakeSettings::default() };
    [("ocean", SceneSpec::Ocean(ocean)), ("lake", SceneSpec::Lake(lake))]
        .into_iter()
        .filter_map(|(name, spec)| spec.build(w, h).ok().map(|scene| (name, scene)))
        .collect()
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
    let mut rows = Vec::new();

    let side = 1024usize;
    for pool_threads in [1, threads] {
        let pool_of_threads = rayon::ThreadPoolBuilder::new().num_threads(pool_threads).build().ok();
        let mut water = rough_pool(side, side);
        let mut run = || water.advance(16);
        let median = match &pool_of_threads {
            Some(p) => p.install(|| median_time(budget, &mut run)),
            None => median_time(budget, &mut run),
        };
        let rate = (side * side * 16) as f64 / median.as_secs_f64() / 1e9;
        rows.push(Row {
            stage: format!("pool simulation, {pool_threads} thread{}", if pool_threads == 1 { "" } else { "s" }),
            size: format!("{side}x{side}"),
            median: median / 16,
            rate: format!("{rate:.2} G cell-updates/s"),
        });
    }

    let terminal = args.terminal;
    for (w, h, label) in [(terminal.width(), terminal.height(), "terminal"), (1920, 1080, "full HD")] {
        let Some(mut scene) = PoolScene::new(w, h, PoolSettings::default()) else { continue };
        let mut frame = Pixmap::new(w, h).expect("a valid size");
        let mut k = 0u32;
        let median = median_time(budget, || {
            k = k.wrapping_add(1);
            scene.drop_stone(Stone::clamped((k * 7919 % w) as i32, (k * 104729 % h) as i32, 3, 128));
            scene.advance(1);
            scene.render(&mut frame);
        });
        rows.push(Row {
            stage: format!("pool frame ({label}): step + picture"),
            size: format!("{w}x{h}"),
            median,
            rate: format!("{:.0} fps", 1.0 / median.as_secs_f64()),
        });
        if label == "terminal" {
            let text_median = median_time(budget, || {
                black_box(halfblock(black_box(&frame)));
            });
            let bytes = halfblock(&frame).len();
            rows.push(Row {
                stage: format!("half-block text ({label}), full frame"),
                size: format!("{}x{} cells", w, h.div_ceil(2)),
                median: text_median,
                rate: tidepool::encode::human_bytes(bytes as u64),
            });
        }
        if label == "full HD" {
            let png_median = median_time(budget, || {
                black_box(png(black_box(&frame)));
            });
            rows.push(Row {
                stage: "PNG encode".into(),
                size: format!("{w}x{h}"),
                median: png_median,
                rate: tidepool::encode::human_bytes(png(&frame).len() as u64),
            });
        }
    }

    // The other scenes, through the same interface the player and animations use.
    for (w, h, ssaa, label) in
        [(terminal.width(), terminal.height(), 1, "terminal"), (1920, 1080, 2, "full HD, ssaa 2")]
    {
        for (name, mut scene) in other_scenes(w, h, ssaa) {
            let mut frame = Pixmap::new(w, h).expect("a valid size");
            let median = median_time(budget, || {
                scene.advance(1);
                scene.render(&mut frame);
            });
            rows.push(Row {
                stage: format!("{name} frame ({label})"),
                size: format!("{w}x{h}"),
                median,
                rate: format!("{:.0} fps", 1.0 / median.as_secs_f64()),
            });
        }
    }

    println!("{:<44} {:>16} {:>11}   rate", "stage", "size", "median");
    for row in &rows {
        println!("{:<44} {:>16} {:>8.3} ms   {}", row.stage, row.size, ms(row.median), row.rate);
    }
    // The interactive budget: at 60 fps a frame has 16.7 ms for sim, picture and encoding.
    let frame = rows.iter().find(|r| r.stage.starts_with("pool frame (terminal)")).map(|r| r.median);
    let encode = rows.iter().find(|r| r.stage.starts_with("half-block text (terminal)")).map(|r| r.median);
    if let (Some(frame), Some(encode)) = (frame, encode) {
        let used = ms(frame + encode);
        let budget_ms = 1000.0 / 60.0;
        let verdict = if used < budget_ms { "yes" } else { "no" };
        println!(
            "\n60 fps in a {}x{}-cell terminal: {verdict} ({used:.2} ms of the {budget_ms:.1} ms frame budget; \
             the simulation runs 60 steps/s)",
            terminal.width(),
            terminal.height().div_ceil(2)
        );
    }
    Ok(())
}
