//! `tidepool serve --bus nats://HOST:PORT --pool NAME`: one pool across many machines. The
//! simulation is deterministic, so the machines (edges) share events, not pictures:
//!
//! - every edge sends its players' requests to the pool's sequencer ([`protocol::Submit`]),
//!   keeps each until the log has it and sends it again meanwhile (`pending.rs`); the
//!   sequencer stamps a request once (`handled.rs`);
//! - one edge at a time holds the sequencer's lease ([`lease`]) in the pool's JetStream
//!   key-value bucket (on a thread and a runtime of its own, where the connection's task runs
//!   too: the players' tasks cannot starve it); it checks every request (bounds, rates per player, per edge, per pool:
//!   [`sequencer`]), and publishes ticks to the pool's JetStream stream: a step every edge may
//!   run to and the events that apply at it;
//! - every edge runs its own copy of the pool from that log ([`lockstep`]) and encodes for its
//!   own players ([`edge`], with the single machine's frame publisher);
//! - the sequencer stores a snapshot of its edge's copy every few seconds (the object store);
//!   an edge that starts late or missed part of the log carries on from it and the log after.
//!
//! Sans-IO where it can be: the protocol, the sequencer, the lease and the lockstep are plain
//! types tested without a server; `link.rs` and `lead.rs` are the async-nats glue.

pub mod edge;
mod handled;
mod heap;
mod lead;
pub mod lease;
mod link;
pub mod lockstep;
#[cfg(test)]
mod memory_tests;
mod pending;
pub mod protocol;
pub mod sequencer;

pub use heap::one_arena;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use crate::{PoolScene, PoolSettings};
use tokio_util::sync::CancellationToken;

use super::game::GameLinks;
use super::limits::PlayerSlots;
use edge::{BusState, EdgeLinks};
use sequencer::SequencerLimits;

/// Messages waiting between the game thread and the bus's tasks, each way.
const QUEUE: usize = 1024;
/// How long the first connection may take.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// What `--bus` and its flags ask for.
#[derive(Clone, Debug)]
pub struct BusOptions {
    /// The NATS server (`nats://`, or `tls://` for TLS).
    pub url: String,
    /// The pool's name (subjects and buckets are named after it).
    pub pool: String,
    /// This edge's name on the bus.
    pub edge: String,
    /// A NATS credentials file (a user's JWT and nkey seed).
    pub credentials: Option<PathBuf>,
    /// A CA certificate to trust for the server's TLS certificate (TLS then required).
    pub ca: Option<PathBuf>,
    /// Where screenshots are saved; `None`: none on this edge.
    pub shots: Option<PathBuf>,
    /// The limits the sequencer applies when this edge holds the role.
    pub limits: SequencerLimits,
}

/// The pool every edge must run alike, and the seed of the sequencer's random stones.
pub struct PoolSpec {
    /// The pool's settings (the first scene of the flags; the bus runs the pool only).
    pub settings: PoolSettings,
    /// Its size in pixels.
    pub size: (u32, u32),
    /// Frames per second.
    pub fps: u32,
    /// The seed of random stones.
    pub seed: u64,
}

impl PoolSpec {
    /// A text that two edges share only when their pools are alike: the version, the size
    /// and every setting (the floor by a hash of its pixels).
    fn fingerprint(&self) -> String {
        let mut settings = self.settings.clone();
        let floor = settings.floor.clone();
        if let Some(dot) = tiny_skia::Pixmap::new(1, 1) {
            settings.floor = dot;
        }
        // FNV-1a: stable across builds, unlike the standard library's hasher.
        let hash = floor
            .data()
            .iter()
            .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
        format!(
            "tidepool {} pool {}x{} seed {} {:?} floor {}x{} {hash:016x}",
            env!("CARGO_PKG_VERSION"),
            self.size.0,
            self.size.1,
            self.seed,
            settings,
            floor.width(),
            floor.height()
        )
    }
}

/// Connects to the bus, opens (or makes) the pool's stream and stores, checks that the pool
/// runs the same settings, and starts the edge: its game thread and the bus's tasks. Errors
/// are one line for the user.
pub async fn start(
    options: BusOptions,
    spec: PoolSpec,
    links: GameLinks,
    players: Arc<PlayerSlots>,
    stop: CancellationToken,
) -> Result<std::thread::JoinHandle<()>, String> {
    let scene = PoolScene::new(spec.size.0, spec.size.1, spec.settings.clone())
        .ok_or_else(|| format!("cannot make a {}x{} pool", spec.size.0, spec.size.1))?;
    let state = Arc::new(BusState::default());
    let fingerprint = spec.fingerprint();
    let (incoming_tx, incoming_rx) = tokio::sync::mpsc::channel(QUEUE);
    let (outgoing_tx, outgoing_rx) = tokio::sync::mpsc::channel(QUEUE);
    let bus = EdgeLinks {
        edge: options.edge.clone(),
        incoming: incoming_rx,
        outgoing: outgoing_tx,
        state: state.clone(),
        shots: options.shots.clone(),
        trace: std::env::var_os("TIDEPOOL_BUS_TRACE").is_some_and(|v| v == "1"),
    };
    let role = lead::Role {
        me: options.edge.clone(),
        size: spec.size,
        steps_per_second: f64::from(spec.settings.steps_per_second),
        seed: spec.seed,
        limits: options.limits,
        snapshots: incoming_tx.clone(),
        state: state.clone(),
    };
    let pool = lead::start(&options, fingerprint, role, stop.clone()).await?;
    let fps = spec.fps;
    let game = std::thread::Builder::new()
        .name("tidepool-edge".into())
        .spawn(move || edge::run(scene, fps, links, bus))
        .map_err(|e| format!("cannot start the game thread ({e})"))?;
    tokio::spawn(link::follow(pool.clone(), incoming_tx, state.clone(), stop.clone()));
    tokio::spawn(link::forward(pool, outgoing_rx, options.edge.clone(), players, stop));
    Ok(game)
}
