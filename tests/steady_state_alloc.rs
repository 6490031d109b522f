//! The interactive loop's steady state must not allocate: a frame (stones, steps, picture)
//! reuses every buffer, for the pool and for the lake. A counting allocator checks it,
//! including rayon's worker threads. This binary holds a single test so no other test's
//! allocations are counted.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use tidepool::render::background;
use tidepool::render::pool::PoolLook;
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
    player_frames();
    lake_player_frames();
}

/// The player's frame path with the lake: time steps, the mesh (sampling, face ids, per-face
/// shading, the per-pixel mirror), cells with the status line, diff encoding; a wind change
/// in the middle (a new lake, nothing reallocated).
fn lake_player_frames() {
    use tidepool::output::color::ColorMode;
    use tidepool::output::diff::{EncodeOptions, Shown, encode_into};
    use tidepool::scene::lake::LakeScene;
    use tidepool::scene::playable::{Action, Playable};
    use tidepool::term::screen::{FrameBuilder, Overlay};

    let (cols, rows) = (160u16, 48u16);
    let (w, h) = tidepool::term::app::picture_size(cols, rows);
    let mut scene = LakeScene::new(tidepool::commands::play::lake_settings(3), w, h).unwrap();
    let mut pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
    let mut builder = FrameBuilder::default();
    let mut shown = Shown::UNKNOWN;
    let mut bytes = Vec::new();
    let options = EncodeOptions { threshold: 0, sync: true };
    let mut run_frames = |scene: &mut LakeScene, frames: u32| {
        for k in 0..frames {
            Playable::step(scene);
            let overlay = Overlay {
                aim: None,
                help: None,
                message: None,
                fps: 30,
                bytes_per_second: 500_000 + u64::from(k),
                stone: 3,
                paused: false,
            };
            let frame = builder.build((cols, rows), scene, &mut pixmap, ColorMode::TrueColor, &overlay);
            bytes.clear();
            encode_into(&mut shown, frame, options, &mut bytes);
        }
    };
    rayon::scope(|_| {
        run_frames(&mut scene, 10);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        run_frames(&mut scene, 30);
        let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert_eq!(during, 0, "lake frames at {cols}x{rows}: {during} allocations in 30 steady-state frames");
        // More wind: the events allocate (once), the frames after them do not.
        for event in scene.resolve(Action::Key('w')) {
            scene.apply(&event);
        }
        run_frames(&mut scene, 2);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        run_frames(&mut scene, 30);
        let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert_eq!(during, 0, "lake frames after a wind change: {during} allocations in 30 frames");
    });
}

/// The player's frame path: step, picture, cells with status line and overlays, diff encoding.
fn player_frames() {
    use tidepool::output::color::ColorMode;
    use tidepool::output::diff::{EncodeOptions, Shown, encode_into};
    use tidepool::scene::playable::Playable;
    use tidepool::term::screen::{FrameBuilder, Overlay};

    let (cols, rows) = (160u16, 48u16);
    let (w, h) = tidepool::term::app::picture_size(cols, rows);
    let settings = PoolSettings { damping: Damping::PAPERS, rain_rate: 0.3, seed: 5, look: PoolLook::default() };
    let mut scene = PoolScene::new(w, h, background::pool_floor(), settings).unwrap();
    let mut pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
    let mut builder = FrameBuilder::default();
    let mut shown = Shown::UNKNOWN;
    let mut bytes = Vec::new();
    let help = tidepool::term::ui::help_lines(&scene.help());
    let message = String::from("saved tidepool-pool-000123.png");
    let options = EncodeOptions { threshold: 0, sync: true };
    let mut run_frames = |frames: u32| {
        for k in 0..frames {
            Playable::step(&mut scene);
            Playable::step(&mut scene);
            let overlay = Overlay {
                aim: Some((k % w, 10)),
                help: (k % 3 == 0).then_some(help.as_slice()),
                message: (k % 2 == 0).then_some(message.as_str()),
                fps: 30,
                bytes_per_second: 1_000_000 + u64::from(k),
                stone: 3,
                paused: false,
            };
            let frame = builder.build((cols, rows), &mut scene, &mut pixmap, ColorMode::TrueColor, &overlay);
            bytes.clear();
            encode_into(&mut shown, frame, options, &mut bytes);
        }
    };
    rayon::scope(|_| {
        run_frames(10);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        run_frames(60);
        let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert_eq!(during, 0, "player frames at {cols}x{rows}: {during} allocations in 60 steady-state frames");
    });
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
