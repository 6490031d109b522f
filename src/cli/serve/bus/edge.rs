//! The edge's game thread: where `serve/game.rs` runs the host on its own clock, an edge runs
//! its [`Lockstep`] copy of the pool from the log, sends its players' requests to the
//! sequencer instead of applying them, and publishes frames to its players the same way
//! ([`Publisher`]). The status line says how the bus is; while it is away, stones are not
//! taken (a stone that no other machine sees would be a lie).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant, SystemTime};

use crate::play::SceneStatus;
use crate::{Controls, PoolScene};
use tiny_skia::Pixmap;
use tokio::sync::{Notify, mpsc, oneshot};

use super::heap::Trim;
use super::lockstep::{Lockstep, Missed};
use super::pending::{MAX_AGE, MAX_WAITING, Pending, PendingCounts};
use super::protocol;
use crate::cli::serve::game::{GameLinks, Publisher, with_players};

/// The longest the thread sleeps before looking at the bus and the stop flag again.
const NAP: Duration = Duration::from_millis(5);
/// How often the requests not yet in the log are looked at for sending again.
const RESEND_CHECK: Duration = Duration::from_millis(50);
/// Most screenshots one edge saves while it runs (players press `s`; the disk is not theirs).
pub const MAX_SHOTS: u32 = 1000;

/// What the bus's tasks hand the game thread.
pub enum Incoming {
    /// A log entry.
    Entry {
        /// Its sequence in the stream.
        seq: u64,
        /// The tick's bytes.
        bytes: Vec<u8>,
    },
    /// Carry on from this snapshot (the log follows from the entry after it).
    Restore(Vec<u8>),
    /// The pool is new: its log starts at the first entry, from step 0.
    Fresh,
    /// The sequencer wants this edge's state for the snapshot store.
    Snapshot(oneshot::Sender<Vec<u8>>),
}

/// What the game thread asks of the bus's tasks.
pub enum Outgoing {
    /// A player's request, encoded.
    Submit(Vec<u8>),
    /// The log had a gap: join again from a snapshot.
    Rejoin,
}

/// How the bus is, for the status line and the log; written by the bus's tasks.
#[derive(Debug, Default)]
pub struct BusState {
    /// Connected to the NATS server.
    pub connected: AtomicBool,
    /// The connection was lost at least once (a `Connected` after it is a return).
    pub lost_once: AtomicBool,
    /// This edge holds the sequencer's lease.
    pub leading: AtomicBool,
    /// The edge has its copy of the pool (from a snapshot or the log's start).
    pub joined: AtomicBool,
    /// Requests not taken because the bus was away (the status line says stones are off).
    pub dropped: AtomicU64,
    /// Log entries skipped as malformed.
    pub bad_entries: AtomicU64,
    /// Told when the connection is back after it was lost: the log's reader starts again at
    /// once (nats-server forgot its consumer; async-nats's own reader noticed only after its
    /// 15 s heartbeat, and the water stood still that long).
    pub back: Notify,
}

impl BusState {
    /// What the status line says about the bus, if anything.
    fn note(&self) -> Option<&'static str> {
        if !self.connected.load(Ordering::Relaxed) {
            Some("bus lost: stones off until it is back")
        } else if !self.joined.load(Ordering::Relaxed) {
            Some("joining the pool")
        } else {
            None
        }
    }
}

/// What the edge's game thread works with.
pub struct EdgeLinks {
    /// This edge's name on the bus.
    pub edge: String,
    /// The bus's messages in.
    pub incoming: mpsc::Receiver<Incoming>,
    /// Requests out.
    pub outgoing: mpsc::Sender<Outgoing>,
    /// How the bus is.
    pub state: Arc<BusState>,
    /// Where screenshots are saved (`--bus-shots`); `None`: not on this edge.
    pub shots: Option<PathBuf>,
    /// Print when each of this edge's requests was sent and when the step that applied it was
    /// published, for the latency measure (`TIDEPOOL_BUS_TRACE=1`).
    pub trace: bool,
}

/// Microseconds since the epoch: a clock every process on one machine shares, for the trace.
fn unix_us() -> u128 {
    SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).map_or(0, |d| d.as_micros())
}

/// Runs the edge's copy of `scene` at `fps` frames a second until `links.stop` is set.
pub fn run(scene: PoolScene, fps: u32, links: GameLinks, mut bus: EdgeLinks) {
    let (w, h) = (scene.width(), scene.height());
    let Some(mut picture) = Pixmap::new(w, h) else { return };
    let mut pool = Lockstep::new(scene);
    let frame_period = Duration::from_secs_f64(1.0 / f64::from(fps.max(1)));
    let mut next_frame = Instant::now();
    let mut publisher = Publisher::default();
    // A number no earlier run of this edge's name used: a restarted edge counts anew.
    let mut pending = Pending::new(&bus.edge, unix_us() as u64);
    let mut said = Said::default();
    let mut next_resend = Instant::now();
    let mut shots_left = MAX_SHOTS;
    // What the process freed goes back to the system every few seconds (`heap.rs`).
    let mut trim = Trim::new(Instant::now());
    let mut requests = links.requests;
    let links = GameLinks { requests: mpsc::channel(1).1, ..links };
    while !links.stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        while let Ok((player, request)) = requests.try_recv() {
            links.stats.requests.fetch_add(1, Ordering::Relaxed);
            let Some(what) = protocol::wire_of(request) else { continue };
            if bus.state.note().is_some() {
                bus.state.dropped.fetch_add(1, Ordering::Relaxed);
                continue;
            }
            // Kept until the log has it: a full queue to the bus's task only delays it.
            let bytes = pending.send(player, what, now);
            if bus.outgoing.try_send(Outgoing::Submit(bytes)).is_ok() && bus.trace {
                eprintln!("bus-trace sent {} {} {}", bus.edge, pending.last(), unix_us());
            }
        }
        take_incoming(&mut pool, &mut bus, &mut pending, now);
        if bus.state.note().is_none() && now >= next_resend {
            next_resend = now + RESEND_CHECK;
            for bytes in pending.due(now) {
                if bus.outgoing.try_send(Outgoing::Submit(bytes)).is_err() {
                    break;
                }
            }
        }
        said.say(&pending, now);
        if let Some(check) = trim.due(now).filter(|_| bus.trace) {
            let (used, free) = (check.used, check.free);
            let took = check.trimmed.map_or_else(|| "not needed".to_string(), |t| format!("{} us", t.as_micros()));
            let flying = crate::cli::serve::flight::all_in_flight();
            let (groups, group_frames) = crate::play::group::alive();
            let models = crate::output::frame::frames_alive();
            eprintln!(
                "bus-trace trim {took}, malloc: {used} bytes in use, {free} free; frames in flight {flying} bytes; \
                 {groups} groups, {group_frames} group frames alive; {models} cell frames alive"
            );
        }
        if now >= next_frame {
            next_frame = (next_frame + frame_period).max(now);
            let shots = bus.shots.clone();
            pool.run(now, &mut |step, scene| save_shot(shots.as_deref(), &mut shots_left, step, scene));
            PoolScene::render(pool.scene_mut(), &mut picture);
            let status = status(&mut pool, links.players.count(), &bus.state);
            publisher.publish(&picture, status, &links, now);
        }
        let sleep = next_frame.saturating_duration_since(Instant::now()).min(NAP);
        if !sleep.is_zero() {
            std::thread::sleep(sleep);
        }
    }
}

/// The edge's log of its requests sent again and given up: at most a line of each a second.
#[derive(Default)]
struct Said {
    told: PendingCounts,
    next: Option<Instant>,
}

impl Said {
    fn say(&mut self, pending: &Pending, now: Instant) {
        if self.next.is_some_and(|t| now < t) {
            return;
        }
        self.next = Some(now + Duration::from_secs(1));
        let (c, t) = (pending.counts(), self.told);
        if c.resent > t.resent {
            eprintln!("bus: sent {} requests again ({} not in the log yet)", c.resent - t.resent, pending.len());
        }
        let (full, old, rejoin) =
            (c.dropped_full - t.dropped_full, c.dropped_old - t.dropped_old, c.dropped_rejoin - t.dropped_rejoin);
        if full + old + rejoin > 0 {
            eprintln!(
                "bus: gave up {} requests not in the log ({full} over the {MAX_WAITING} kept, {old} older than {} s, {rejoin} on joining again)",
                full + old + rejoin,
                MAX_AGE.as_secs()
            );
        }
        self.told = c;
    }
}

/// Takes what the bus sent: log entries, a snapshot to start from, a request for ours.
fn take_incoming(pool: &mut Lockstep, bus: &mut EdgeLinks, pending: &mut Pending, now: Instant) {
    while let Ok(message) = bus.incoming.try_recv() {
        match message {
            Incoming::Entry { seq, bytes } => match (seq > pool.last_seq(), pool.receive(seq, &bytes, now)) {
                (false, Ok(())) => {} // delivered again after a reconnect
                (true, Ok(())) => {
                    // Read again (checked already): which of this edge's requests it settles.
                    if let Ok(tick) = serde_json::from_slice::<protocol::Tick>(&bytes) {
                        pending.taken(seq, &tick);
                        if bus.trace {
                            trace_applied(&tick, bytes.len(), &bus.edge, pool.step());
                        }
                    }
                }
                (_, Err(Missed::Gap { expected, got })) => {
                    eprintln!("bus: log entry {got} came after {}; joining again from a snapshot", expected - 1);
                    bus.state.joined.store(false, Ordering::Relaxed);
                    let _ = bus.outgoing.try_send(Outgoing::Rejoin);
                }
                (_, Err(Missed::Bad(why))) => {
                    bus.state.bad_entries.fetch_add(1, Ordering::Relaxed);
                    eprintln!("bus: log entry {seq} skipped (every edge skips it): {why}");
                }
            },
            Incoming::Restore(bytes) => match pool.restore(&bytes, now) {
                Ok(()) => {
                    eprintln!("bus: joined from a snapshot at step {} (log entry {})", pool.step(), pool.last_seq());
                    pending.rejoined(pool.last_seq());
                    bus.state.joined.store(true, Ordering::Relaxed);
                }
                Err(why) => eprintln!("bus: {why}; waiting for another snapshot"),
            },
            Incoming::Fresh => {
                eprintln!("bus: joined a new pool at its start");
                bus.state.joined.store(true, Ordering::Relaxed);
            }
            Incoming::Snapshot(reply) => {
                let _ = reply.send(pool.snapshot());
            }
        }
    }
}

/// The trace's line for every event of another edge in a tick just taken (the ring shows at
/// its step, within a frame and the lead of this moment).
fn trace_applied(tick: &protocol::Tick, bytes: usize, me: &str, step: u64) {
    for e in tick.events.iter().filter(|e| e.edge != me) {
        eprintln!("bus-trace taken {} {} at {step} for {} {} {bytes}", e.edge, e.n, tick.step, unix_us());
    }
}

/// The status line: the pool's players, the bus's note, the scene's summary.
fn status(pool: &mut Lockstep, here: usize, state: &BusState) -> SceneStatus {
    let (players, paused) = ((pool.players() as usize).max(here), pool.paused());
    let scene = pool.scene_mut();
    let mut summary = String::new();
    scene.status(&mut summary);
    let detail = match state.note() {
        Some(note) => with_players(players, &format!("{note} \u{b7} {summary}")),
        None => with_players(players, &summary),
    };
    SceneStatus {
        name: "pool",
        detail,
        takes_stones: state.note().is_none(),
        hints: scene.hints(),
        keys: scene.help(),
        paused,
    }
}

/// Saves the scene's picture at `step` as `tidepool-pool-STEP.png` in `dir`: every edge that
/// keeps screenshots writes the same bytes for the same step.
fn save_shot(dir: Option<&std::path::Path>, left: &mut u32, step: u64, scene: &mut PoolScene) {
    let Some(dir) = dir else { return };
    if *left == 0 {
        eprintln!("bus: screenshot at step {step} not saved: {MAX_SHOTS} saved already");
        return;
    }
    *left -= 1;
    let Some(mut out) = Pixmap::new(scene.width(), scene.height()) else { return };
    PoolScene::render(scene, &mut out);
    let path = dir.join(format!("tidepool-pool-{step:06}.png"));
    match crate::cli::files::write_file(&path, &crate::encode::png(&out)) {
        Ok(()) => eprintln!("bus: saved {}", path.display()),
        Err(e) => eprintln!("bus: screenshot at step {step} not saved: {e}"),
    }
}
