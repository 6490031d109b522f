//! The interactive loop's steady state must not allocate: a frame (steps, picture, status line
//! and overlays, diff encoding, the write) reuses every buffer, for the pool and the lake. A
//! counting allocator checks it, across every thread (rayon's workers and the frame writer).
//! The player runs for real here, through `tidepool::testing::run` (the terminal door) on a fake terminal: this is
//! also the proof that the loop runs on any byte stream.
//! The ocean is the exception it measures: its foam makes four small vectors anew for every
//! picture (`FoamClock::weights` and the two `taps` of `FoamTracker::update`,
//! `src/sim/foam.rs`: the memory's weights as f64 and f32, the taps of this step and the
//! next; about 1.3 kB together), whatever the size of the picture or its mesh (the mesh itself
//! is drawn into reused buffers). So an ocean frame may allocate [`OCEAN_PER_FRAME`] times.
//! This binary holds a single test so no other test's allocations are counted.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use tidepool::play::{Bandwidth, GraphicsRequest, HostConfig, ScreenConfig};
use tidepool::play::{ColorMode, EncodeOptions};
use tidepool::testing::{PlayConfig, TerminalInput};
use tidepool::{LakeSettings, OceanSettings, PoolScene, PoolSettings, Scene, SceneSpec, Stone};

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

/// Frames written before the count starts (scratch buffers, deques, the help overlay).
const WARM_UP: usize = 10;
/// Frames counted.
const COUNTED: usize = 60;
/// The ocean's allocations a frame: the foam's four vectors (measured: 240 in 60 frames in
/// eight runs of nine, 244 in one, at 160x48 cells and 5,055 triangles).
const OCEAN_PER_FRAME: usize = 4;
/// Allocations the ocean's 60 frames may make beyond four a frame: one picture drawn for every
/// tenth frame on top of its own (the one run above the measure drew one extra picture, four
/// allocations). A frame that allocated once per triangle would make thousands.
const OCEAN_HEADROOM: usize = OCEAN_PER_FRAME * COUNTED / 10;

#[test]
fn frames_allocate_nothing_after_warm_up() {
    // Start every rayon worker first: threads starting up allocate, concurrently with
    // whatever is being measured.
    rayon::broadcast(|_| ());
    pool_frames();
    let pool = PoolSettings { rain_rate: 0.3, seed: 5, ..PoolSettings::default() };
    assert_eq!(player_frames(SceneSpec::Pool(pool)), 0, "pool player frames: no allocation");
    assert_eq!(player_frames(SceneSpec::Pool(coherent(0.3, 5))), 0, "the player's pool: no allocation");
    let lake = SceneSpec::Lake(LakeSettings::default());
    assert_eq!(player_frames(lake), 0, "lake player frames: no allocation");
    let ocean = SceneSpec::Ocean(OceanSettings::default());
    let allocations = player_frames(ocean);
    let most = OCEAN_PER_FRAME * COUNTED + OCEAN_HEADROOM;
    eprintln!("ocean player frames: {allocations} allocations in {COUNTED} frames (at most {most})");
    assert!(allocations <= most, "ocean: {allocations} allocations in {COUNTED} frames, more than {most}");
    lake_frames_after_a_wind_change();
}

/// A 160x48 terminal that sends keys once, at the start: `?` (the help overlay, which
/// allocates its lines when it opens) and `l` (the aim marker).
struct FakeTerminal {
    keys: Option<&'static [u8]>,
}

impl TerminalInput for FakeTerminal {
    fn read(&mut self, buf: &mut Vec<u8>, timeout: Duration) -> io::Result<bool> {
        match self.keys.take() {
            Some(keys) => buf.extend_from_slice(keys),
            None => std::thread::sleep(timeout),
        }
        Ok(true)
    }

    fn size(&mut self) -> io::Result<(u16, u16)> {
        Ok((160, 48))
    }
}

/// Counts the frames written; notes the allocation count after the warm-up and after the
/// counted frames, then asks the player to quit.
struct FrameCounter {
    frames: usize,
    marks: Arc<Mutex<Vec<usize>>>,
    quit: Arc<AtomicBool>,
}

impl io::Write for FrameCounter {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        Ok(bytes.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        // The player flushes once after each whole frame.
        self.frames += 1;
        if self.frames == WARM_UP || self.frames == WARM_UP + COUNTED {
            let count = ALLOCATIONS.load(Ordering::Relaxed);
            let mut marks = self.marks.lock().unwrap();
            marks.push(count);
            if marks.len() == 2 {
                self.quit.store(true, Ordering::SeqCst);
            }
        }
        Ok(())
    }
}

/// The player's real loop on a fake terminal, at 60 fps (a step every frame, so every frame is
/// drawn and sent); returns the
/// allocations of [`COUNTED`] frames after [`WARM_UP`].
fn player_frames(scene: SceneSpec) -> usize {
    let quit = Arc::new(AtomicBool::new(false));
    let marks = Arc::new(Mutex::new(Vec::with_capacity(2)));
    let config = PlayConfig {
        host: HostConfig { scenes: vec![scene], seed: 1, record: None, screenshots: false },
        screen: ScreenConfig {
            fps: 60,
            bandwidth: Bandwidth::Unlimited,
            color: ColorMode::TrueColor,
            color_auto: false,
            colour_hint: false,
            encode: EncodeOptions { threshold: 0, sync: true },
            graphics: GraphicsRequest::Auto,
            probe: None,
            link_path: tidepool::play::LinkPath::Direct,
        },
        greeting: Some("a greeting in the status line".into()),
        storage: None,
        quit: Arc::clone(&quit),
    };
    let output = FrameCounter { frames: 0, marks: Arc::clone(&marks), quit };
    tidepool::testing::run(&mut FakeTerminal { keys: Some(b"?l") }, output, config).unwrap();
    let marks = marks.lock().unwrap();
    marks[1] - marks[0]
}

/// The player's pool: two cells a pixel, 30 steps a second, gusts.
fn coherent(rain_rate: f64, seed: u64) -> PoolSettings {
    PoolSettings {
        rain_rate,
        seed,
        grid: 2,
        steps_per_second: 30,
        breeze: 1.0,
        breeze_style: tidepool::BreezeStyle::Gusts,
        ..PoolSettings::default()
    }
}

/// The pool's own frames: a terminal-sized pool (one thread) and a full-HD one (row bands on
/// rayon), the papers' and the player's.
fn pool_frames() {
    for (w, h, settings) in [
        (160u32, 94u32, PoolSettings { rain_rate: 0.5, seed: 3, ..PoolSettings::default() }),
        (1920, 1080, PoolSettings { rain_rate: 0.5, seed: 3, ..PoolSettings::default() }),
        (160, 94, coherent(0.5, 3)),
        (480, 300, coherent(0.5, 3)),
    ] {
        let mut scene = PoolScene::new(w, h, settings).unwrap();
        let mut frame = tiny_skia::Pixmap::new(w, h).unwrap();
        let mut run_frames = |scene: &mut PoolScene, frames: u32| {
            for k in 0..frames {
                scene.drop_stone(Stone::clamped((k * 37 % w) as i32, (k * 23 % h) as i32, 4, 100));
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
        assert_eq!(during, 0, "{w}x{h} grid {}: {during} allocations in 60 steady-state frames", scene.grid());
    }
}

/// A wind change makes a new lake (its events allocate, once); the frames after it reuse
/// every buffer as before.
fn lake_frames_after_a_wind_change() {
    use tidepool::{Action, Controls};
    let mut scene = tidepool::LakeScene::new(LakeSettings::default(), 160, 94).unwrap();
    let mut pixmap = tiny_skia::Pixmap::new(160, 94).unwrap();
    rayon::scope(|_| {
        for _ in 0..5 {
            Scene::advance(&mut scene, 1);
            Scene::render(&mut scene, &mut pixmap);
        }
        for event in scene.resolve(Action::Damping(false)) {
            scene.apply(&event);
        }
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        for _ in 0..30 {
            Scene::advance(&mut scene, 1);
            Scene::render(&mut scene, &mut pixmap);
        }
        let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert_eq!(during, 0, "lake frames after a wind change: {during} allocations in 30 frames");
    });
}
