//! Benchmarks of the ripple pool: `sim/ripple_step`, `render/pool`, `render/pool_player`,
//! `output/png`.
//!
//! `sim/ripple_step` runs a plain transliteration of the papers' scalar loop next to tidepool's
//! step in the same run, and prints the speed-ups at the end, so every run shows how much
//! faster the real step is on this machine.
//!
//! `render/pool_player` is issue 29's renderer figure: the player's pool at 480x282 in wall
//! time; `cpu/pool_player` the same frame in the process's CPU time (all threads), which the
//! load of other processes does not inflate.
//!
//! Run: `cargo bench --bench pool` (add `-- sim/` to run one group, `-- pool_player` for the
//! player's frame).

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use tidepool::testing::RipplePool;
use tidepool::{BreezeStyle, Damping, Event, PoolLook, PoolScene, PoolSettings, Scene, Stone};
use tiny_skia::Pixmap;

/// The papers' loop, transliterated: index arithmetic, an i32 sum, shifts, store, swap.
struct PapersPool {
    buf1: Vec<i16>,
    buf2: Vec<i16>,
    width: usize,
    height: usize,
}

impl PapersPool {
    fn step(&mut self) {
        let w = self.width;
        for y in 1..self.height - 1 {
            for x in 1..w - 1 {
                let i = y * w + x;
                let sum = self.buf1[i - 1] as i32
                    + self.buf1[i + 1] as i32
                    + self.buf1[i - w] as i32
                    + self.buf1[i + w] as i32;
                let mut v = (sum >> 1) - self.buf2[i] as i32;
                v -= v >> 5;
                self.buf2[i] = v as i16;
            }
        }
        std::mem::swap(&mut self.buf1, &mut self.buf2);
    }
}

fn rough_pool(side: usize) -> RipplePool {
    let mut pool = RipplePool::new(side, side, Damping::PAPERS);
    for k in 0..64 {
        let x = (k * 7919 % side) as i32;
        let y = (k * 104729 % side) as i32;
        pool.drop_stone(Stone::clamped(x, y, 6, 200));
    }
    pool.advance(20);
    pool
}

fn thread_pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap()
}

fn ripple_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("sim/ripple_step");
    group.sample_size(20);
    let one = thread_pool(1);
    let two = thread_pool(2);
    for side in [256usize, 1024, 2048] {
        let pool = rough_pool(side);
        group.throughput(Throughput::Elements((side * side) as u64));
        let mut papers = PapersPool {
            buf1: pool.heights().to_vec(),
            buf2: pool.previous_heights().to_vec(),
            width: side,
            height: side,
        };
        group.bench_function(BenchmarkId::new("papers_scalar", side), |b| b.iter(|| papers.step()));
        let mut single = pool.clone();
        group.bench_function(BenchmarkId::new("step_1thread", side), |b| one.install(|| b.iter(|| single.step())));
        // Blocked runs: one iteration is 16 steps, so report 16 steps' worth of cells.
        group.throughput(Throughput::Elements((side * side * 16) as u64));
        let mut blocked = pool.clone();
        group.bench_function(BenchmarkId::new("advance16_1thread", side), |b| {
            one.install(|| b.iter(|| blocked.advance(16)))
        });
        let mut parallel = pool.clone();
        group.bench_function(BenchmarkId::new("advance16_2threads", side), |b| {
            two.install(|| b.iter(|| parallel.advance(16)))
        });
    }
    group.finish();
}

fn render_pool(c: &mut Criterion) {
    let mut group = c.benchmark_group("render/pool");
    group.sample_size(20);
    for (w, h) in [(160u32, 96u32), (1920, 1080)] {
        // Lively water: heavy rain (one papers' raindrop per 100,000 pixels per step) for 200
        // steps leaves rings over the whole picture, the busy case for refraction and light.
        // Each look gets its own scene with the same seed, so the same water.
        let lively = |look| {
            let rain_rate = f64::from(w * h) / 100_000.0;
            let mut scene = PoolScene::new(w, h, PoolSettings { rain_rate, seed: 7, look, ..PoolSettings::default() })
                .expect("a benchmark-sized pool");
            scene.advance(200);
            scene.apply(&Event::Rain(0.0));
            scene
        };
        let mut out = Pixmap::new(w, h).unwrap();
        let mut full = lively(PoolLook::default());
        group.throughput(Throughput::Elements(u64::from(w * h)));
        group.bench_function(BenchmarkId::new("refract_shade", format!("{w}x{h}")), |b| {
            b.iter(|| full.render(&mut out))
        });
        // The same without caustics and without light, to see what each costs.
        let bare = PoolLook { caustics: None, ..PoolLook::default() };
        let mut no_caustics = lively(bare);
        group.bench_function(BenchmarkId::new("refract_shade_no_caustics", format!("{w}x{h}")), |b| {
            b.iter(|| no_caustics.render(&mut out))
        });
        let mut refract_only = lively(PoolLook { shading: false, ..bare });
        group.bench_function(BenchmarkId::new("refract_only", format!("{w}x{h}")), |b| {
            b.iter(|| refract_only.render(&mut out))
        });
        // A frame of the interactive loop: a raindrop, a step, the picture. The drops keep
        // the water moving so the filtered (fractional-offset) path is what gets measured.
        let mut k = 0u32;
        group.bench_function(BenchmarkId::new("step_and_render", format!("{w}x{h}")), |b| {
            b.iter(|| {
                k = k.wrapping_add(1);
                full.drop_stone(Stone::clamped((k * 7919 % w) as i32, (k * 104729 % h) as i32, 3, 128));
                Scene::advance(&mut full, 1);
                full.render(&mut out)
            })
        });
    }
    group.finish();
}

/// The player's pool as the pixel modes draw it: 480x282 pixels (160x48 cells of 8x16 pixels
/// less the status row, within the player's scene cap) with the player's defaults (`play`'s
/// `PoolDefaults::PLAYER`: a grid of two cells a pixel, 30 steps a second, gusts at level 1, rain
/// 0.01; the default look: caustics, shading) and a few stones' rings on it.
fn player_pool() -> PoolScene {
    let settings = PoolSettings {
        rain_rate: 0.01,
        breeze: 1.0,
        breeze_style: BreezeStyle::Gusts,
        grid: 2,
        steps_per_second: 30,
        seed: 1,
        ..PoolSettings::default()
    };
    let mut scene = PoolScene::new(480, 282, settings).expect("the player's pool");
    for k in 0..6u32 {
        scene.drop_stone(Stone::clamped((k * 7919 % 480) as i32, (k * 104729 % 282) as i32, 4, 128));
        Scene::advance(&mut scene, 20);
    }
    scene
}

/// Frame `k` (counted up first) of the player's pool: a stone every 30 frames (a second), one
/// step, the picture.
fn player_frame(scene: &mut PoolScene, out: &mut Pixmap, k: &mut u32) {
    *k = k.wrapping_add(1);
    if k.is_multiple_of(30) {
        scene.drop_stone(Stone::clamped((*k * 7919 % 480) as i32, (*k * 104729 % 282) as i32, 3, 128));
    }
    Scene::advance(scene, 1);
    scene.render(out)
}

/// The picture of the player's pool (issue 29's "the pool's frame at 480x282"): `render` is the
/// picture alone, `frame` one step (1/30 s at 30 steps a second) and the picture, with a stone
/// a second as a player drops them; each on rayon's pool (all cores) and on one thread (what
/// the frame costs in CPU time).
fn render_player_pool(c: &mut Criterion) {
    let mut group = c.benchmark_group("render/pool_player");
    group.sample_size(30);
    group.throughput(Throughput::Elements(480 * 282));
    let one = thread_pool(1);
    let mut out = Pixmap::new(480, 282).unwrap();
    // Each iteration runs on the given pool (`install` costs microseconds, the frame milliseconds).
    for (suffix, pool) in [("", None), ("_1thread", Some(&one))] {
        let run = |f: &mut (dyn FnMut() + Send)| match pool {
            Some(p) => p.install(f),
            None => f(),
        };
        let mut scene = player_pool();
        group.bench_function(format!("render{suffix}/480x282"), |b| b.iter(|| run(&mut || scene.render(&mut out))));
        let mut k = 0u32;
        group.bench_function(format!("frame{suffix}/480x282"), |b| {
            b.iter(|| run(&mut || player_frame(&mut scene, &mut out, &mut k)))
        });
    }
    group.finish();
}

/// The process's CPU time (every thread, user and system: `CLOCK_PROCESS_CPUTIME_ID`) as a
/// criterion measurement: what a frame costs a user's `top`, rayon's idle workers included,
/// and unlike the wall clock not inflated when other processes share the cores.
struct ProcessCpu(WallTime);

impl ProcessCpu {
    fn now() -> std::time::Duration {
        let t = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
        std::time::Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
    }
}

impl Measurement for ProcessCpu {
    type Intermediate = std::time::Duration;
    type Value = std::time::Duration;

    fn start(&self) -> Self::Intermediate {
        ProcessCpu::now()
    }

    fn end(&self, start: Self::Intermediate) -> Self::Value {
        ProcessCpu::now().saturating_sub(start)
    }

    fn add(&self, a: &Self::Value, b: &Self::Value) -> Self::Value {
        *a + *b
    }

    fn zero(&self) -> Self::Value {
        std::time::Duration::ZERO
    }

    fn to_f64(&self, value: &Self::Value) -> f64 {
        value.as_nanos() as f64
    }

    fn formatter(&self) -> &dyn ValueFormatter {
        self.0.formatter()
    }
}

/// `render/pool_player`'s frame in CPU time ([`ProcessCpu`]) on rayon's pool.
fn cpu_player_pool(c: &mut Criterion<ProcessCpu>) {
    let mut group = c.benchmark_group("cpu/pool_player");
    group.sample_size(30);
    let mut out = Pixmap::new(480, 282).unwrap();
    let mut scene = player_pool();
    group.bench_function("render/480x282", |b| b.iter(|| scene.render(&mut out)));
    let mut k = 0u32;
    group.bench_function("frame/480x282", |b| b.iter(|| player_frame(&mut scene, &mut out, &mut k)));
    group.finish();
}

fn output_png(c: &mut Criterion) {
    let mut group = c.benchmark_group("output/png");
    group.sample_size(10);
    let mut pool = PoolScene::new(1920, 1080, PoolSettings::default()).unwrap();
    let floor = pool.snapshot().unwrap();
    group.bench_function("encode_1920x1080", |b| b.iter(|| tidepool::encode::png(&floor)));
    group.finish();
}

/// Reads criterion's median estimate (ns) of one benchmark from `target/criterion`.
fn median_ns(group: &str, bench: &str) -> Option<f64> {
    let dir = std::env::var_os("CARGO_TARGET_DIR").map(std::path::PathBuf::from).unwrap_or_else(|| "target".into());
    let path = dir.join("criterion").join(group.replace('/', "_")).join(bench).join("new/estimates.json");
    let text = std::fs::read_to_string(path).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    json["median"]["point_estimate"].as_f64()
}

fn print_speedups() {
    println!("\nsim/ripple_step, medians of this run (cell updates per second, speed-up over the papers' loop):");
    for side in [256, 1024, 2048] {
        let cells = (side * side) as f64;
        let Some(base) = median_ns("sim/ripple_step", &format!("papers_scalar/{side}")) else { continue };
        let rate = |ns: f64, steps: f64| cells * steps / ns; // Gcells/s
        print!("  {side}x{side}: papers {:.2} G/s", rate(base, 1.0));
        for (name, steps) in [("step_1thread", 1.0), ("advance16_1thread", 16.0), ("advance16_2threads", 16.0)] {
            if let Some(ns) = median_ns("sim/ripple_step", &format!("{name}/{side}")) {
                print!(", {name} {:.2} G/s ({:.1}x)", rate(ns, steps), base * steps / ns);
            }
        }
        if let (Some(a), Some(b)) = (
            median_ns("sim/ripple_step", &format!("advance16_1thread/{side}")),
            median_ns("sim/ripple_step", &format!("advance16_2threads/{side}")),
        ) {
            print!(", 2 threads / 1 thread {:.2}x", a / b);
        }
        println!();
    }
}

criterion_group!(benches, ripple_step, render_pool, render_player_pool, output_png);
criterion_group! {
    name = cpu;
    config = Criterion::default().with_measurement(ProcessCpu(WallTime));
    targets = cpu_player_pool
}

fn main() {
    benches();
    cpu();
    Criterion::default().configure_from_args().final_summary();
    print_speedups();
}
