//! `tidepool bench`: how fast this machine runs tidepool, stage by stage, in a few seconds —
//! the way a user checks whether a small VPS can run the interactive pool at 60 fps.

use std::hint::black_box;
use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use crate::cli::BenchArgs;
use crate::error::Result;
use crate::output::{halfblock, png};
use crate::render::background;
use crate::render::ocean::OceanView;
use crate::render::pool::PoolLook;
use crate::render::texture::SeaTexture;
use crate::scene::lake::{LakeScene, LakeSettings};
use crate::scene::ocean::{OceanScene, OceanSettings};
use crate::scene::playable::Playable;
use crate::scene::pool::{PoolScene, PoolSettings};
use crate::sim::lake::LakeParams;
use crate::sim::ocean::SeaParams;
use crate::sim::ripple::{Damping, RipplePool, Stone};
use crate::simd::Simd;

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
        pool.drop_stone(Stone { x: (k * 7919 % w) as i32, y: (k * 104729 % h) as i32, radius: 5, weight: 160 });
    }
    pool.advance(10);
    pool
}

/// The scenes besides the pool, at their defaults, drawing `w x h` with `ssaa` supersampling.
fn other_scenes(w: u32, h: u32, ssaa: u32) -> Vec<(&'static str, Box<dyn Playable>)> {
    let mut scenes: Vec<(&'static str, Box<dyn Playable>)> = Vec::new();
    let ocean = OceanSettings {
        sea: SeaParams {
            wind_m_s: crate::cli::ocean::DEFAULT_WIND_M_S,
            wind_from_deg: 330.0,
            seed: 1,
            ..SeaParams::default()
        },
        view: OceanView { ssaa, ..OceanView::default() },
    };
    if let Some(scene) = OceanScene::new(ocean, w, h, SeaTexture::builtin()) {
        scenes.push(("ocean", Box::new(scene)));
    }
    let lake = LakeSettings { lake: LakeParams::default(), ssaa };
    if let Some(scene) = LakeScene::new(lake, w, h) {
        scenes.push(("lake", Box::new(scene)));
    }
    scenes
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Runs `tidepool bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    let budget = Duration::from_secs_f64(args.seconds.max(0.05));
    let threads = rayon::current_num_threads();
    println!(
        "tidepool bench: {threads} threads, SIMD kernel {:?}, {:.1} s per workload",
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

    let floor = background::pool_floor();
    let terminal = args.terminal;
    for (w, h, label) in [(terminal.width, terminal.height, "terminal"), (1920, 1080, "full HD")] {
        let settings = PoolSettings { damping: Damping::PAPERS, rain_rate: 0.0, seed: 1, look: PoolLook::default() };
        let Some(mut scene) = PoolScene::new(w, h, floor.clone(), settings) else { continue };
        let mut frame = Pixmap::new(w, h).expect("a valid size");
        let mut k = 0u32;
        let median = median_time(budget, || {
            k = k.wrapping_add(1);
            scene.drop_stone(Stone { x: (k * 7919 % w) as i32, y: (k * 104729 % h) as i32, radius: 3, weight: 128 });
            scene.step();
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
                black_box(halfblock::encode(black_box(&frame)));
            });
            let bytes = halfblock::encode(&frame).len();
            rows.push(Row {
                stage: format!("half-block text ({label}), full frame"),
                size: format!("{}x{} cells", w, h.div_ceil(2)),
                median: text_median,
                rate: format!("{:.0} KB", bytes as f64 / 1024.0),
            });
        }
        if label == "full HD" {
            let png_median = median_time(budget, || {
                black_box(png::encode(black_box(&frame)));
            });
            rows.push(Row {
                stage: "PNG encode".into(),
                size: format!("{w}x{h}"),
                median: png_median,
                rate: format!("{:.0} KB", png::encode(&frame).len() as f64 / 1024.0),
            });
        }
    }

    // The other scenes, through the same interface the player and animations use.
    for (w, h, ssaa, label) in [(terminal.width, terminal.height, 1, "terminal"), (1920, 1080, 2, "full HD, ssaa 2")] {
        for (name, mut scene) in other_scenes(w, h, ssaa) {
            let mut frame = Pixmap::new(w, h).expect("a valid size");
            let median = median_time(budget, || {
                scene.step();
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
            terminal.width,
            terminal.height.div_ceil(2)
        );
    }
    Ok(())
}
