//! The one shared scene: a [`Host`] on its own thread, stepped on its fixed clock whatever the
//! players do, rendered once per frame and fitted once per distinct picture size, then published
//! to every player through a `watch` slot (newest wins: a slow player skips pictures, nothing
//! queues).
//!
//! Players never touch the host: their seats send [`Request`]s through a bounded queue, and the
//! game applies them before the next step.
//!
//! Players whose screens are alike (size, colours, link class: a [`GroupKey`]) share their
//! frames: for every key that two or more players have, the game encodes the frame once
//! ([`Groups`], in parallel across groups) and publishes the group's last frames with the
//! pictures; each player takes them while its terminal shows the group's model
//! ([`crate::play::Membership`]). Server CPU then grows with the groups, not the players.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::play::group::{GroupFeed, GroupKey, Groups};
use crate::play::{Fit, Host, Request, SceneStatus};
use tiny_skia::Pixmap;
use tokio::sync::{mpsc, watch};

use super::limits::PlayerSlots;

/// Most requests waiting for the next step, from all players together; more are dropped.
pub const REQUEST_QUEUE: usize = 1024;
/// The longest the game thread sleeps before looking at its stop flag again.
const MAX_SLEEP: Duration = Duration::from_millis(20);

/// Everything published after one frame.
#[derive(Debug, Default)]
pub struct SharedFrame {
    /// Frames published so far (this one included).
    pub number: u64,
    /// What the status line and the help say, players counted.
    pub status: Arc<SceneStatus>,
    /// The scene fitted into each picture size a player's screen asked for.
    pub pictures: HashMap<(u32, u32), Arc<Pixmap>>,
    /// Each group's last frames.
    pub groups: HashMap<GroupKey, GroupFeed>,
}

/// How a player's screen wants the scene.
#[derive(Clone, Debug)]
pub struct Viewing {
    /// How the scene fits its picture (one picture per distinct size).
    pub fit: Fit,
    /// The group it belongs in, if any.
    pub group: Option<GroupKey>,
    /// The text of its group's note (the passing message its status line shows), if any.
    pub note: Option<Arc<str>>,
}

/// Every player's [`Viewing`], by player id.
pub type Fits = Arc<Mutex<HashMap<u64, Viewing>>>;

/// Counters the tests and the load report read.
#[derive(Debug, Default)]
pub struct GameStats {
    /// Frames published.
    pub frames: AtomicU64,
    /// Pictures fitted (one per distinct size per frame).
    pub pictures: AtomicU64,
    /// Requests applied.
    pub requests: AtomicU64,
    /// Group frames encoded (one per group per frame that changed something).
    pub group_frames: AtomicU64,
}

/// What the game thread reads and writes.
pub struct GameLinks {
    /// Requests from the players, with the player's id.
    pub requests: mpsc::Receiver<(u64, Request)>,
    /// The fits to draw.
    pub fits: Fits,
    /// Players now (for the status line).
    pub players: Arc<PlayerSlots>,
    /// Where pictures go.
    pub publish: watch::Sender<Arc<SharedFrame>>,
    /// Counters.
    pub stats: Arc<GameStats>,
    /// Set to stop the thread.
    pub stop: Arc<AtomicBool>,
}

/// Publishes frames: the scene fitted once per picture size the players asked for, the
/// groups' frames, the status. Its buffers are kept between frames. Shared by the single
/// machine's game and the bus's edge (`bus/edge.rs`).
#[derive(Default)]
pub struct Publisher {
    number: u64,
    pictures: HashMap<(u32, u32), Arc<Pixmap>>,
    groups: Groups,
}

impl Publisher {
    /// Publishes `scene` (just rendered) with `status` to every player of `links`.
    pub fn publish(&mut self, scene: &Pixmap, status: SceneStatus, links: &GameLinks, now: Instant) {
        self.number += 1;
        let viewing: Vec<Viewing> = links.fits.lock().unwrap_or_else(|p| p.into_inner()).values().cloned().collect();
        let mut drawn = HashMap::with_capacity(viewing.len());
        for fit in viewing.iter().map(|v| v.fit) {
            if drawn.contains_key(&fit.target()) {
                continue;
            }
            // Last frame's picture of this size, when no player holds it any more.
            let old = self.pictures.remove(&fit.target()).and_then(|p| Arc::try_unwrap(p).ok());
            if let Some(picture) = fit.fitted(scene, old) {
                drawn.insert(fit.target(), Arc::new(picture));
                links.stats.pictures.fetch_add(1, Ordering::Relaxed);
            }
        }
        self.groups.keep(viewing.iter().filter_map(|v| Some((v.group?, v.note.clone()))), now);
        let encoded = self.groups.encode(&drawn, &status, now);
        links.stats.group_frames.fetch_add(encoded, Ordering::Relaxed);
        let feeds = self.groups.feeds();
        links.stats.frames.fetch_add(1, Ordering::Relaxed);
        // Never waits: a player still busy with an older picture simply sees a later one.
        let frame = SharedFrame { number: self.number, status: Arc::new(status), pictures: drawn, groups: feeds };
        let previous = links.publish.send_replace(Arc::new(frame));
        // Last frame's pictures come back for reuse once no player holds them.
        self.pictures = Arc::try_unwrap(previous).map(|f| f.pictures).unwrap_or_default();
    }
}

/// The status line's detail with the player count first (a passing message may cover the end
/// of a narrow status line): `3 playing · ` and then `rest`.
pub fn with_players(players: usize, rest: &str) -> String {
    let mut detail = String::with_capacity(rest.len() + 16);
    let _ = write!(detail, "{players} playing \u{b7} {rest}");
    detail
}

/// Runs `host` on this thread at `fps` frames a second until `links.stop` is set.
pub fn run(mut host: Host, fps: u32, mut links: GameLinks) {
    let (w, h) = host.size();
    let Some(mut scene) = Pixmap::new(w, h) else { return };
    let frame_period = Duration::from_secs_f64(1.0 / f64::from(fps.max(1)));
    let mut next_frame = Instant::now();
    let mut publisher = Publisher::default();
    while !links.stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        while let Ok((_, request)) = links.requests.try_recv() {
            links.stats.requests.fetch_add(1, Ordering::Relaxed);
            // A message would go to one person: the shared pool has nobody to say it to.
            let _ = host.apply(request, now);
        }
        host.advance(now);
        if now >= next_frame {
            // A late frame is not made up for: the next one is a period from now.
            next_frame = (next_frame + frame_period).max(now);
            host.render(&mut scene);
            let players = links.players.count();
            let mut status = host.status().clone();
            status.detail = with_players(players, &host.status().detail);
            publisher.publish(&scene, status, &links, now);
        }
        let wake = host.next_due().map_or(next_frame, |s| s.min(next_frame));
        let sleep = wake.saturating_duration_since(Instant::now()).min(MAX_SLEEP);
        if !sleep.is_zero() {
            std::thread::sleep(sleep);
        }
    }
    drop(links.publish);
}
