//! The one shared scene: stepped on its own fixed clock by one thread, whatever the players
//! do, rendered once per frame and scaled once per distinct terminal size, then published to
//! every player through a `watch` slot (newest wins: a slow player skips pictures, nothing
//! queues).
//!
//! Players never touch the scene: they send [`Shared`] actions through a bounded queue, and the
//! game applies them before the next step.

use std::collections::{BTreeSet, HashMap};
use std::fmt::Write as _;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tidepool::player::{SceneInfo, SimClock, picture_size};
use tidepool::{Action, Playable, SceneSpec};
use tiny_skia::Pixmap;
use tokio::sync::{mpsc, watch};

use super::letterbox::Letterbox;
use super::limits::PlayerSlots;

/// Most actions waiting for the next step, from all players together; more are dropped.
pub const ACTION_QUEUE: usize = 1024;
/// Random stones use their own generator, seeded from `--seed` xor this (as in the player).
const STONE_SEED_MIX: u64 = 0x5354_4f4e_4553_0001;
/// The longest the game thread sleeps before looking at its stop flag again.
const MAX_SLEEP: Duration = Duration::from_millis(20);

/// A terminal size in cells: (columns, rows).
pub type Cells = (u16, u16);

/// What a player can do to the shared scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shared {
    /// An action in scene pixels (stones, stirs, rain, clear, damping, scene keys).
    Act(Action),
    /// A stone of this radius at a random spot.
    RandomStone(u32),
    /// Pause or resume the shared clock.
    Pause,
    /// The next scene, for everyone.
    NextScene,
}

/// Everything published after one frame.
#[derive(Debug)]
pub struct Pictures {
    /// Frames published so far (this one included).
    pub number: u64,
    /// Whether the shared clock is paused.
    pub paused: bool,
    /// The status line's and the help's view of the scene, players counted.
    pub info: Arc<SceneInfo>,
    /// One picture per distinct terminal size, letterboxed to it.
    pub pictures: HashMap<Cells, Arc<Pixmap>>,
}

/// The terminal sizes players have now (player id → cells); the game draws one picture each.
pub type Sizes = Arc<Mutex<HashMap<u64, Cells>>>;

/// Counters the tests and the load report read.
#[derive(Debug, Default)]
pub struct GameStats {
    /// Frames published.
    pub frames: AtomicU64,
    /// Pictures scaled (one per distinct size per frame).
    pub pictures: AtomicU64,
    /// Actions applied.
    pub actions: AtomicU64,
}

/// How the game runs.
pub struct GameOptions {
    /// The scenes `tab` cycles through; the first is shown at the start.
    pub scenes: Vec<SceneSpec>,
    /// The shared scene's size in pixels.
    pub size: (u32, u32),
    /// Frames per second.
    pub fps: u32,
    /// Seed of the random stones.
    pub seed: u64,
}

/// What the game thread reads and writes.
pub struct GameLinks {
    /// Actions from the players.
    pub actions: mpsc::Receiver<Shared>,
    /// The sizes to draw.
    pub sizes: Sizes,
    /// Players now (for the status line).
    pub players: Arc<PlayerSlots>,
    /// Where pictures go.
    pub publish: watch::Sender<Arc<Pictures>>,
    /// Counters.
    pub stats: Arc<GameStats>,
    /// Set to stop the thread.
    pub stop: Arc<AtomicBool>,
}

/// The first, empty value of the `watch` slot.
pub fn nothing_yet(info: SceneInfo) -> Arc<Pictures> {
    Arc::new(Pictures { number: 0, paused: false, info: Arc::new(info), pictures: HashMap::new() })
}

/// Builds the first scene (so a bad scene setting fails before the server starts).
pub fn first_scene(options: &GameOptions) -> tidepool::Result<Box<dyn Playable>> {
    let first = options.scenes.first().ok_or_else(|| {
        tidepool::Error::Value(tidepool::ValueError::new("scenes", "the server needs at least one scene"))
    })?;
    first.build(options.size.0, options.size.1)
}

/// Runs the game on this thread until `links.stop` is set.
pub fn run(options: GameOptions, mut scene: Box<dyn Playable>, mut links: GameLinks) {
    let (w, h) = options.size;
    let Some(mut pixmap) = Pixmap::new(w, h) else { return };
    let mut current = 0;
    let start = Instant::now();
    let mut clock = SimClock::new(scene.steps_per_second(), start);
    let frame_period = Duration::from_secs_f64(1.0 / f64::from(options.fps.max(1)));
    let mut next_frame = start;
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed ^ STONE_SEED_MIX);
    let mut info = SceneInfo::of(scene.as_ref());
    // The scene's own status, kept between frames (`Controls::status` rewrites it whole).
    let mut scene_detail = String::new();
    let mut number = 0u64;
    while !links.stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        while let Ok(action) = links.actions.try_recv() {
            links.stats.actions.fetch_add(1, Ordering::Relaxed);
            match action {
                Shared::Act(action) => {
                    for event in scene.resolve(action) {
                        scene.apply(&event);
                    }
                }
                Shared::RandomStone(radius) => {
                    let (x, y) = (rng.random_range(0..w) as i32, rng.random_range(0..h) as i32);
                    for event in scene.resolve(Action::Stone { x, y, radius, big: false }) {
                        scene.apply(&event);
                    }
                }
                Shared::Pause => clock.set_paused(!clock.paused(), now),
                Shared::NextScene if options.scenes.len() > 1 => {
                    let next = (current + 1) % options.scenes.len();
                    if let Ok(built) = options.scenes[next].build(w, h) {
                        scene = built;
                        current = next;
                        clock = SimClock::new(scene.steps_per_second(), now);
                        info = SceneInfo::of(scene.as_ref());
                    }
                }
                Shared::NextScene => {}
            }
        }
        let due = clock.due(now);
        scene.advance(due);
        if now >= next_frame {
            // A late frame is not made up for: the next one is a period from now.
            next_frame = (next_frame + frame_period).max(now);
            number += 1;
            scene.render(&mut pixmap);
            let players = links.players.count();
            // The count first: a passing message may cover the end of a narrow status line.
            info.detail.clear();
            let _ = write!(info.detail, "{players} playing \u{b7} ");
            scene.status(&mut scene_detail);
            info.detail.push_str(&scene_detail);
            let wanted: BTreeSet<Cells> =
                links.sizes.lock().unwrap_or_else(|p| p.into_inner()).values().copied().collect();
            let mut pictures = HashMap::with_capacity(wanted.len());
            for cells in wanted {
                let fit = Letterbox::fit((w, h), picture_size(cells.0, cells.1));
                if let Some(picture) = fit.draw(&pixmap) {
                    pictures.insert(cells, Arc::new(picture));
                    links.stats.pictures.fetch_add(1, Ordering::Relaxed);
                }
            }
            links.stats.frames.fetch_add(1, Ordering::Relaxed);
            // Never waits: a player still busy with an older picture simply sees a later one.
            links.publish.send_replace(Arc::new(Pictures {
                number,
                paused: clock.paused(),
                info: Arc::new(info.clone()),
                pictures,
            }));
        }
        let wake = clock.next_due().map_or(next_frame, |s| s.min(next_frame));
        let sleep = wake.saturating_duration_since(Instant::now()).min(MAX_SLEEP);
        if !sleep.is_zero() {
            std::thread::sleep(sleep);
        }
    }
    drop(links.publish);
}
