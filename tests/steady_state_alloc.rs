//! The interactive loop's steady state must not allocate: a frame (stones, steps, picture)
//! reuses every buffer, for the pool and the lake. A counting allocator checks it, including
//! rayon's worker threads. The ocean is the exception it measures: tiny-skia's `fill_path`
//! builds each triangle's edge list in a fresh `Vec` (there is no way to hand it a buffer), so
//! an ocean frame allocates about once per triangle drawn, and nothing else.
//! This binary holds a single test so no other test's allocations are counted.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use tidepool::render::background;
use tidepool::render::pool::PoolLook;
use tidepool::scene::lake::LakeScene;
use tidepool::scene::pool::{PoolScene, PoolSettings};
use tidepool::sim::ripple::{Damping, Stone};

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

#[test]
fn frames_allocate_nothing_after_warm_up() {
    pool_frames();
    let (w, h) = tidepool::term::app::picture_size(160, 48);
    let settings = PoolSettings { damping: Damping::PAPERS, rain_rate: 0.3, seed: 5, look: PoolLook::default() };
    let pool = PoolScene::new(w, h, background::pool_floor(), settings).unwrap();
    assert_eq!(player_frames(Box::new(pool)), 0, "pool player frames: no allocation");
    let lake = LakeScene::new(tidepool::commands::play::lake_settings(3), w, h).unwrap();
    assert_eq!(player_frames(Box::new(lake)), 0, "lake player frames: no allocation");
    ocean_frames_allocate_only_inside_tiny_skia(w, h);
    lake_frames_after_a_wind_change();
}

/// The ocean's frames allocate only in tiny-skia's path filling: at most one allocation per
/// triangle (and none of tidepool's own buffers).
fn ocean_frames_allocate_only_inside_tiny_skia(w: u32, h: u32) {
    use tidepool::render::ocean::OceanView;
    use tidepool::render::texture::SeaTexture;
    use tidepool::scene::ocean::{OceanScene, OceanSettings};
    use tidepool::sim::ocean::SeaParams;
    let settings = OceanSettings {
        sea: SeaParams { wind_m_s: 10.0, wind_from_deg: 330.0, seed: 1, ..SeaParams::default() },
        view: OceanView::default(),
    };
    let mut scene = OceanScene::new(settings, w, h, SeaTexture::builtin()).unwrap();
    tidepool::scene::playable::Playable::render(&mut scene, &mut tiny_skia::Pixmap::new(w, h).unwrap());
    let triangles = scene.renderer().triangle_count();
    let during = player_frames(Box::new(scene));
    let per_frame = during as f64 / 60.0;
    eprintln!("ocean player frames: {per_frame:.0} allocations a frame, {triangles} triangles");
    assert!(per_frame <= triangles as f64, "ocean: {per_frame} allocations a frame for {triangles} triangles");
}

/// A wind change makes a new lake (its events allocate, once); the frames after it reuse
/// every buffer as before.
fn lake_frames_after_a_wind_change() {
    use tidepool::scene::playable::{Action, Playable};
    let (w, h) = tidepool::term::app::picture_size(160, 48);
    let mut scene = LakeScene::new(tidepool::commands::play::lake_settings(3), w, h).unwrap();
    let mut pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
    rayon::scope(|_| {
        for _ in 0..5 {
            scene.step();
            Playable::render(&mut scene, &mut pixmap);
        }
        for event in scene.resolve(Action::Damping(false)) {
            scene.apply(&event);
        }
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        for _ in 0..30 {
            scene.step();
            Playable::render(&mut scene, &mut pixmap);
        }
        let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert_eq!(during, 0, "lake frames after a wind change: {during} allocations in 30 frames");
    });
}

/// The player's frame path for a scene: steps, picture, cells with status line and overlays,
/// diff encoding. Returns the allocations of 60 frames after a warm-up of 10.
fn player_frames(mut scene: Box<dyn tidepool::scene::playable::Playable>) -> usize {
    use tidepool::output::color::ColorMode;
    use tidepool::output::diff::{EncodeOptions, Shown, encode_into};
    use tidepool::term::screen::{FrameBuilder, Overlay};

    let (cols, rows) = (160u16, 48u16);
    let (w, h) = tidepool::term::app::picture_size(cols, rows);
    let mut pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
    let mut builder = FrameBuilder::default();
    let mut shown = Shown::UNKNOWN;
    let mut bytes = Vec::new();
    let help = tidepool::term::ui::help_lines(&scene.help(), true);
    let message = String::from("saved tidepool-pool-000123.png");
    let options = EncodeOptions { threshold: 0, sync: true };
    let mut run_frames = |frames: u32| {
        for k in 0..frames {
            scene.step();
            scene.step();
            let overlay = Overlay {
                aim: Some((k % w, 10)),
                help: (k % 3 == 0).then_some(help.as_slice()),
                message: (k % 2 == 0).then_some(message.as_str()),
                fps: 30,
                bytes_per_second: 1_000_000 + u64::from(k),
                stone: 3,
                paused: false,
            };
            let frame = builder.build((cols, rows), scene.as_mut(), &mut pixmap, ColorMode::TrueColor, &overlay);
            bytes.clear();
            encode_into(&mut shown, frame, options, &mut bytes);
        }
    };
    rayon::scope(|_| {
        run_frames(10);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        run_frames(60);
        ALLOCATIONS.load(Ordering::Relaxed) - before
    })
}

fn pool_frames() {
    // Start every rayon worker first: threads starting up allocate, concurrently with
    // whatever is being measured.
    rayon::broadcast(|_| ());
    // A terminal-sized pool (one thread) and a full-HD one (row bands on rayon).
    for (w, h) in [(160u32, 94u32), (1920, 1080)] {
        let settings = PoolSettings { damping: Damping::PAPERS, rain_rate: 0.5, seed: 3, look: PoolLook::default() };
        let mut scene = PoolScene::new(w, h, background::pool_floor(), settings).unwrap();
        let mut frame = tiny_skia::Pixmap::new(w, h).unwrap();
        let mut run_frames = |scene: &mut PoolScene, frames: u32| {
            for k in 0..frames {
                scene.drop_stone(Stone { x: (k * 37 % w) as i32, y: (k * 23 % h) as i32, radius: 4, weight: 100 });
                scene.advance(2);
                scene.render(&mut frame);
            }
        };
        // The loop runs on a rayon worker, as the player's does: jobs then go to the worker's
        // own deque. (Jobs injected from outside the pool land in rayon's global injector,
        // which allocates a block every 63 jobs.)
        let during = rayon::scope(|_| {
            run_frames(&mut scene, 5); // warm-up: scratch buffers, deques
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            run_frames(&mut scene, 60);
            ALLOCATIONS.load(Ordering::Relaxed) - before
        });
        assert_eq!(during, 0, "{w}x{h}: {during} allocations in 60 steady-state frames");
    }
}
