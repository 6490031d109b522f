//! What every connection and player of the server shares: the limits, the shared scene's
//! channels, the counters. Its own module so that the server (which accepts connections), the
//! handler (one per connection) and the viewer (one per player) all read it without importing
//! each other in a circle.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use russh::server::Config;
use tokio::sync::{mpsc, watch};
use tokio_util::sync::CancellationToken;
use tokio_util::task::TaskTracker;

use super::authorized_keys::AllowList;
use crate::output::bucket::ByteBucket;
use crate::play::Request;

use super::game::{Fits, GameStats, SharedFrame};
use super::limits::{ConnTracker, Limits, PlayerSlots};

/// Counters for tests, logs and the load report.
#[derive(Debug, Default)]
pub struct Stats {
    /// TCP connections accepted and handed to SSH.
    pub accepted: AtomicU64,
    /// Connections closed at accept (total or per-address limit).
    pub refused_at_accept: AtomicU64,
    /// Connections cut by the handshake deadline.
    pub handshake_timeouts: AtomicU64,
    /// Successful authentications.
    pub authenticated: AtomicU64,
    /// Clients told the pool is full.
    pub pool_full: AtomicU64,
    /// Requests and channel opens refused (exec, subsystem, forwarding, agent, X11, …).
    pub refused_requests: AtomicU64,
    /// Frames sent to clients.
    pub frames_sent: AtomicU64,
    /// Pictures a client skipped because it had not taken the previous one yet.
    pub frames_skipped: AtomicU64,
    /// Frames skipped by the server-wide outbound byte rate.
    pub frames_dropped_rate: AtomicU64,
    /// Players sent away for idling.
    pub idle_kicks: AtomicU64,
    /// Players cut for not taking a frame within the stall timeout.
    pub stall_kicks: AtomicU64,
    /// Requests dropped by the per-player rate or a full queue.
    pub actions_dropped: AtomicU64,
    /// Scene keys dropped by the per-player or the all-players rate.
    pub scene_keys_dropped: AtomicU64,
    /// New terminal sizes that waited for the resize rate.
    pub resizes_deferred: AtomicU64,
    /// Packets of key bytes dropped because the player's task was behind.
    pub input_dropped: AtomicU64,
}

impl Stats {
    /// One line for the log at exit.
    pub fn summary(&self, game: &GameStats) -> String {
        let get = |c: &AtomicU64| c.load(Ordering::Relaxed);
        format!(
            "{} connections ({} refused at accept, {} handshake timeouts), {} players, {} told the pool is full, \
             {} requests refused, {} frames published, {} sent, {} skipped, {} idle, {} stalled, \
             {} actions applied, {} dropped, {} scene keys dropped, {} resizes deferred, {} group frames encoded",
            get(&self.accepted),
            get(&self.refused_at_accept),
            get(&self.handshake_timeouts),
            get(&self.authenticated),
            get(&self.pool_full),
            get(&self.refused_requests),
            get(&game.frames),
            get(&self.frames_sent),
            get(&self.frames_skipped),
            get(&self.idle_kicks),
            get(&self.stall_kicks),
            get(&game.requests),
            get(&self.actions_dropped),
            get(&self.scene_keys_dropped),
            get(&self.resizes_deferred),
            get(&game.group_frames),
        )
    }
}

/// State shared by the accept loop, every connection and every player.
pub(crate) struct Hub {
    pub limits: Limits,
    pub allow: Option<AllowList>,
    pub config: Arc<Config>,
    pub tracker: Arc<ConnTracker>,
    pub players: Arc<PlayerSlots>,
    /// "Please leave": players say goodbye and close.
    pub shutdown: CancellationToken,
    /// Parent of every connection's kill switch.
    pub cut_all: CancellationToken,
    pub frames: watch::Receiver<Arc<SharedFrame>>,
    pub fits: Fits,
    /// Players' requests with the player's id, to the game.
    pub requests: mpsc::Sender<(u64, Request)>,
    /// All players' frames together, bytes a second.
    pub outbound: Mutex<ByteBucket>,
    /// All players' scene keys together.
    pub scene_keys: Mutex<ByteBucket>,
    pub stats: Arc<Stats>,
    pub tasks: TaskTracker,
    pub next_id: AtomicU64,
    /// The shared scene's size in pixels.
    pub scene_size: (u32, u32),
    /// Frames per second of the shared scene (each player's screen draws at most as often).
    pub fps: u32,
    /// Whether `s` asks the game for a screenshot (a bus edge with `--bus-shots`); otherwise
    /// players are told screenshots are off.
    pub screenshots: bool,
}
