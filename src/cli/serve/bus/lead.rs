//! The async glue of the sequencer's role: every edge watches the lease; the one that holds
//! it reads the log's last tick, takes the players' requests, publishes a tick every
//! [`TICK_PERIOD`] (each publish fenced by the log's expected last sequence, so a sequencer
//! that lost the lease without knowing cannot write after the new one), refreshes the lease,
//! and stores its edge's snapshot every [`SNAPSHOT_PERIOD`].

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use async_nats::jetstream::kv::{self, Operation};
use async_nats::jetstream::message::PublishMessage;
use futures_util::StreamExt;
use tokio::sync::{mpsc, oneshot};
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;

use super::BusOptions;
use super::edge::{BusState, Incoming};
use super::lease::{self, Lease, LeaseStep};
use super::link::{self, PoolLink, SNAPSHOT_OBJECT};
use super::lockstep::MAX_SNAPSHOT_BYTES;
use super::protocol::{self, Tick};
use super::sequencer::{Sequencer, SequencerLimits, TICK_PERIOD};

/// How often the sequencer stores a snapshot.
pub const SNAPSHOT_PERIOD: Duration = Duration::from_secs(5);
/// The lease's key.
const LEASE_KEY: &str = "sequencer";
/// Log entries read back for the last good tick.
const LOOK_BACK: u64 = 64;
/// Refusals printed a second at most (a flood is counted, not printed).
const REFUSALS_PRINTED_PER_SECOND: u32 = 5;

/// The refusals' log: the first few of each second in full, the rest counted and summed up
/// with the last reason (a flood must not flood the log).
#[derive(Default)]
struct Refusals {
    second: Option<Instant>,
    printed: u32,
    unprinted: u64,
    last: String,
}

impl Refusals {
    fn note(&mut self, why: String, total: u64, now: Instant) {
        if self.second.is_none_or(|s| now.duration_since(s) >= Duration::from_secs(1)) {
            self.summarize(now);
            (self.second, self.printed) = (Some(now), 0);
        }
        if self.printed < REFUSALS_PRINTED_PER_SECOND {
            self.printed += 1;
            eprintln!("bus: refused a request ({total} refused so far): {why}");
        } else {
            self.unprinted += 1;
            self.last = why;
        }
    }

    fn summarize(&mut self, now: Instant) {
        let due = self.second.is_some_and(|s| now.duration_since(s) >= Duration::from_secs(1));
        if due && self.unprinted > 0 {
            eprintln!("bus: refused {} more requests in a second; the last: {}", self.unprinted, self.last);
            self.unprinted = 0;
        }
    }
}

/// Most ticks kept whose fate is not known yet (a tick not acknowledged, with requests in it).
const MAX_LIMBO: usize = 64;

/// This term's ticks that were not acknowledged and carry requests, all published after the
/// same log entry (the sequencer's last known one): at most one of them can be written there
/// (the log's expected-last-sequence fence). Once that entry is known, the others never will
/// be, and their requests are forgotten so that their edges' next sends are taken (a stone
/// in no tick is lost; one in two ticks would be applied twice).
#[derive(Default)]
struct Limbo {
    ticks: Vec<(Vec<u8>, Tick)>,
}

impl Limbo {
    fn keep(&mut self, bytes: Vec<u8>, tick: Tick) {
        if tick.events.is_empty() && tick.settled.is_empty() {
            return;
        }
        if self.ticks.len() >= MAX_LIMBO {
            // Its requests stay handled: if it was not written they are lost (said).
            self.ticks.remove(0);
            eprintln!("bus: {MAX_LIMBO} ticks not acknowledged; the oldest one's requests are no longer sent again");
        }
        self.ticks.push((bytes, tick));
    }

    /// The entry after the one they were fenced on is known: `written` (its bytes), or
    /// `None` when a later tick took it.
    fn resolve(&mut self, written: Option<&[u8]>, seq: &mut Sequencer) {
        for (bytes, tick) in self.ticks.drain(..) {
            if written != Some(bytes.as_slice()) {
                seq.forget(&tick);
            }
        }
    }
}

/// Renews the lease every [`lease::REFRESH`] until `give_up`; cancels `lost` and ends only
/// when the compare-and-set says another edge holds it. Returns the lease as it left it.
///
/// A renewal that fails otherwise (the bus away, a timeout) is tried again at the next
/// refresh, however long that takes: the clock alone never gives the role up. That is safe
/// because nothing rests on it: a standby takes the key only with a compare-and-set on the
/// revision this edge last wrote (so this edge learns of it on its next try), and a tick this
/// edge publishes meanwhile is refused by the log's expected-last-sequence check. Giving up by
/// the clock made a restart of nats-server move the role for nothing: the holder gave up
/// while the bus was away, and requests sent once it was back found no sequencer
/// (docs/serve/bus.md, round 4). Each try waits at most a refresh, so a try lost with the
/// old connection does not hold the next one back once the bus returns.
async fn keep(
    kv: kv::Store,
    me: String,
    mut lease: Lease,
    lost: CancellationToken,
    give_up: CancellationToken,
) -> Lease {
    let mut refresh = tokio::time::interval(lease::REFRESH);
    refresh.set_missed_tick_behavior(MissedTickBehavior::Delay);
    let mut failing = false;
    loop {
        tokio::select! {
            _ = give_up.cancelled() => return lease,
            _ = refresh.tick() => {}
        }
        let Some(revision) = lease.held() else {
            lost.cancel();
            return lease;
        };
        let wrote = tokio::select! {
            _ = give_up.cancelled() => return lease,
            wrote = tokio::time::timeout(lease::REFRESH, kv.update(LEASE_KEY, me.clone().into(), revision)) => wrote,
        };
        match wrote {
            Ok(Ok(r)) => {
                if std::mem::take(&mut failing) {
                    eprintln!("bus: the lease renewed again (revision {r})");
                }
                lease.wrote(r, Instant::now());
            }
            Ok(Err(e)) if e.kind() == kv::UpdateErrorKind::WrongLastRevision => {
                match ours(&kv, &me).await {
                    // A renewal that seemed to fail landed after all (sent when the bus came
                    // back): the key still names this edge, and no other wrote since.
                    Some(Some(r)) => lease.wrote(r, Instant::now()),
                    Some(None) => {
                        eprintln!("bus: cannot renew the lease ({e}): another edge holds it");
                        lease.refused();
                        lost.cancel();
                        return lease;
                    }
                    None => failing = true,
                }
            }
            failed => {
                let why = match failed {
                    Ok(Err(e)) => e.to_string(),
                    _ => "timed out".to_owned(),
                };
                if !std::mem::replace(&mut failing, true) {
                    eprintln!("bus: cannot renew the lease ({why}); trying again, still the sequencer");
                }
            }
        }
    }
}

/// The lease key's revision if it names `me` (`Some(None)`: another edge, or no key; `None`:
/// it could not be read).
async fn ours(kv: &kv::Store, me: &str) -> Option<Option<u64>> {
    let entry = tokio::time::timeout(lease::REFRESH, kv.entry(LEASE_KEY)).await.ok()?.ok()?;
    Some(entry.filter(|e| e.operation == Operation::Put && e.value.as_ref() == me.as_bytes()).map(|e| e.revision))
}

/// What the sequencer's role needs besides its connection to the bus.
pub struct Role {
    /// This edge's name.
    pub me: String,
    /// The scene's size.
    pub size: (u32, u32),
    /// The pool's pace.
    pub steps_per_second: f64,
    /// The random stones' seed.
    pub seed: u64,
    /// The limits.
    pub limits: SequencerLimits,
    /// To ask the game thread for a snapshot.
    pub snapshots: mpsc::Sender<Incoming>,
    /// How the bus is.
    pub state: Arc<BusState>,
}

/// Starts this edge's part in the sequencer's role (watching the lease; sequencing while it
/// holds it) on a thread of its own with a runtime of its own, and opens the edge's
/// connection to the bus there: the connection's own task (every message in and out) runs on
/// that runtime too, and the edge's other tasks share it from theirs.
///
/// Why a thread: the players' tasks (their frames' encoding) run on the server's runtime, and
/// at load 8 to 12 on 2 cores a lease whose renewal shared their workers (and their
/// connection's task) missed its second: the role moved six times in five minutes, keys waited
/// seconds and 2 % of stones were refused (docs/serve/bus.md, round 2). Here only a dead or
/// cut-off edge loses the role. One connection, not one for the role and one for the edge: the
/// status line's `bus lost` then speaks for both. Returns the pool once the connection is
/// open (its error otherwise).
pub async fn start(
    options: &BusOptions,
    fingerprint: String,
    role: Role,
    stop: CancellationToken,
) -> Result<Arc<PoolLink>, String> {
    let (opened_tx, opened) = oneshot::channel();
    let options = options.clone();
    std::thread::Builder::new()
        .name("tidepool-sequencer".into())
        .spawn(move || {
            let runtime = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
                Ok(runtime) => runtime,
                Err(e) => {
                    let _ = opened_tx.send(Err(format!("cannot start the sequencer's runtime ({e})")));
                    return;
                }
            };
            runtime.block_on(async move {
                match link::open(&options, &fingerprint, role.state.clone()).await {
                    Ok(pool) => {
                        let pool = Arc::new(pool);
                        let _ = opened_tx.send(Ok(pool.clone()));
                        Leader { pool, role }.run(stop).await;
                    }
                    Err(e) => {
                        let _ = opened_tx.send(Err(e));
                    }
                }
            });
        })
        .map_err(|e| format!("cannot start the sequencer's thread ({e})"))?;
    opened.await.map_err(|_| "the sequencer's thread ended while starting".to_owned())?
}

/// An edge's part in the sequencer's role, on its own thread ([`start`]).
struct Leader {
    /// The pool (its connection's task on the role's runtime).
    pool: Arc<PoolLink>,
    /// The rest.
    role: Role,
}

/// Why a sequencer stopped.
enum Ended {
    Stopped,
    LostLease,
}

impl Leader {
    /// Watches the lease until `stop`; sequences while it holds it.
    pub async fn run(self, stop: CancellationToken) {
        let mut lease = Lease::new(&self.role.me);
        while !stop.is_cancelled() {
            let read = match self.role.state.connected.load(Ordering::Relaxed) {
                true => self.pool.kv.entry(LEASE_KEY).await.ok(),
                false => None,
            };
            let Some(entry) = read.map(|entry| entry.filter(|e| e.operation == Operation::Put)) else {
                // Blind for a while: the holder's silence meanwhile proves nothing.
                lease.lost_sight();
                tokio::select! { _ = stop.cancelled() => return, _ = tokio::time::sleep(lease::POLL) => continue }
            };
            let now = Instant::now();
            let holder = entry.as_ref().map(|e| (String::from_utf8_lossy(&e.value).into_owned(), e.revision));
            let wrote = match lease.observe(holder.as_ref().map(|(h, r)| (h.as_str(), *r)), now) {
                LeaseStep::Wait => None,
                LeaseStep::Create => Some(self.pool.kv.create(LEASE_KEY, self.role.me.clone().into()).await.ok()),
                LeaseStep::Update(r) => Some(self.pool.kv.update(LEASE_KEY, self.role.me.clone().into(), r).await.ok()),
            };
            match wrote {
                Some(Some(revision)) => lease.wrote(revision, Instant::now()),
                Some(None) => lease.refused(),
                None => {}
            }
            if lease.held().is_some() {
                if let Some(previous) = holder.filter(|(h, _)| *h != self.role.me) {
                    eprintln!("bus: took the sequencer's role over from {}", previous.0);
                }
                self.role.state.leading.store(true, Ordering::Relaxed);
                let ended = self.sequence(&mut lease, &stop).await;
                self.role.state.leading.store(false, Ordering::Relaxed);
                match ended {
                    Ended::Stopped => return,
                    Ended::LostLease => eprintln!("bus: this edge is no longer the sequencer"),
                }
            }
            tokio::select! { _ = stop.cancelled() => return, _ = tokio::time::sleep(lease::POLL) => {} }
        }
    }

    /// The log's last sequence, and its last good tick (none in a new pool): the last entries
    /// may be another writer's garbage, so up to [`LOOK_BACK`] entries are read back.
    async fn last_tick(&self) -> Result<(u64, Option<Tick>), String> {
        let last = match self.pool.stream.get_last_raw_message_by_subject(&self.pool.names.log).await {
            Ok(message) => message,
            Err(e) if e.to_string().contains("no message") || e.to_string().contains("not found") => {
                return Ok((0, None));
            }
            Err(e) => return Err(e.to_string()),
        };
        let end = last.sequence;
        if let Ok(tick) = protocol::read_tick(&last.payload, self.role.size) {
            return Ok((end, Some(tick)));
        }
        for seq in (end.saturating_sub(LOOK_BACK)..end).rev().filter(|&s| s > 0) {
            if let Ok(message) = self.pool.stream.get_raw_message(seq).await
                && let Ok(tick) = protocol::read_tick(&message.payload, self.role.size)
            {
                return Ok((end, Some(tick)));
            }
        }
        Ok((end, None))
    }

    /// Sequences while the lease holds.
    async fn sequence(&self, lease: &mut Lease, stop: &CancellationToken) -> Ended {
        let Some(term) = lease.held() else { return Ended::LostLease };
        let (last_seq, last) = match self.last_tick().await {
            Ok(x) => x,
            Err(e) => {
                eprintln!("bus: cannot read the log's end ({e}); giving the role up");
                return Ended::LostLease;
            }
        };
        let now = Instant::now();
        let seq = Sequencer::new(
            self.role.size,
            self.role.steps_per_second,
            self.role.limits,
            self.role.seed,
            last.as_ref(),
            (term, last_seq),
            now,
        );
        eprintln!("bus: this edge is the sequencer (term {term}), after log entry {last_seq}");
        // The lease is renewed by a task of its own: a tick's publish waiting for its
        // acknowledgement (up to a second when nats-server is slow) must not delay it.
        let (lost, give_up) = (CancellationToken::new(), CancellationToken::new());
        let held = std::mem::replace(lease, Lease::new(&self.role.me));
        let keeper =
            tokio::spawn(keep(self.pool.kv.clone(), self.role.me.clone(), held, lost.clone(), give_up.clone()));
        let ended = self.sequence_held(seq, (term, last_seq), &lost, stop).await;
        give_up.cancel();
        if let Ok(back) = keeper.await {
            *lease = back;
        }
        ended
    }

    /// The sequencer's loop: requests in, a tick out every [`TICK_PERIOD`], a snapshot every
    /// [`SNAPSHOT_PERIOD`], until `lost` (the lease's keeper gave up) or `stop`.
    async fn sequence_held(
        &self,
        mut seq: Sequencer,
        (term, mut last_seq): (u64, u64),
        lost: &CancellationToken,
        stop: &CancellationToken,
    ) -> Ended {
        let (Ok(mut submits), Ok(mut presence)) = (
            self.pool.client.subscribe(self.pool.names.submit.clone()).await,
            self.pool.client.subscribe(self.pool.names.presence.clone()).await,
        ) else {
            return Ended::LostLease;
        };
        let mut ticks = tokio::time::interval(TICK_PERIOD);
        let mut snapshot = tokio::time::interval(SNAPSHOT_PERIOD);
        let mut refusals = Refusals::default();
        // Ticks not acknowledged in a row (said once when it starts and once when it ends).
        let mut unacked = 0u32;
        let mut limbo = Limbo::default();
        loop {
            tokio::select! {
                _ = stop.cancelled() => return Ended::Stopped,
                Some(m) = submits.next() => {
                    let now = Instant::now();
                    if let Err(why) = seq.submit(&m.payload, now) {
                        refusals.note(why.0, seq.counts().refused, now);
                    }
                }
                Some(m) = presence.next() => { let _ = seq.presence(&m.payload, Instant::now()); }
                _ = ticks.tick() => {
                    refusals.summarize(Instant::now());
                    let tick = seq.tick(Instant::now());
                    let bytes = protocol::bytes_of(&tick);
                    match self.publish(bytes.clone(), last_seq).await {
                        Ok(s) => {
                            if unacked > 0 {
                                eprintln!("bus: ticks acknowledged again (entry {s}) after {unacked} that were not");
                            }
                            // This tick took the entry after `last_seq`: no other can.
                            limbo.resolve(None, &mut seq);
                            (last_seq, unacked) = (s, 0);
                        }
                        // Not acknowledged (the bus away, or the log's fence): carry on after
                        // the log's end only if this term wrote it.
                        Err(why) => {
                            if unacked == 0 {
                                eprintln!("bus: a tick after log entry {last_seq} not acknowledged ({why}); trying again");
                            }
                            unacked += 1;
                            limbo.keep(bytes, tick);
                            match self.end_of_term(term, last_seq).await {
                                Some(Some((s, written))) => {
                                    if s != last_seq {
                                        limbo.resolve(Some(&written), &mut seq);
                                    }
                                    last_seq = s;
                                }
                                Some(None) => {
                                    eprintln!("bus: the log moved on after entry {last_seq} without this sequencer; giving the sequencer's role up");
                                    return Ended::LostLease;
                                }
                                // Unreadable: whether the tick was written is known once the
                                // entry after `last_seq` is (the next tick tries again after it).
                                None => {}
                            }
                        }
                    }
                }
                _ = lost.cancelled() => return Ended::LostLease,
                _ = snapshot.tick() => self.store_snapshot().await,
            }
        }
    }

    /// Publishes a tick after log entry `after`; its sequence, or why it was not acknowledged
    /// (refused by the log's fence, or the bus away: it may have been written).
    async fn publish(&self, tick: Vec<u8>, after: u64) -> Result<u64, String> {
        let message = PublishMessage::build().payload(tick.into()).expected_last_sequence(after);
        let ack = self.pool.js.send_publish(self.pool.names.log.clone(), message).await.map_err(|e| e.to_string())?;
        ack.await.map(|ack| ack.sequence).map_err(|e| e.to_string())
    }

    /// After a tick of `term` that was not acknowledged: the log's last entry and its bytes if
    /// this term wrote it or the log is still at `after` (`Some(None)`: something else wrote it, another
    /// sequencer or a stray writer; `None`: the log could not be read). A publish whose
    /// acknowledgement was lost with the connection may have been written (a request queued
    /// while the bus was away is sent when it is back); a later tick would then be fenced out
    /// after it, and the role would move for nothing. Reading the end and carrying on after
    /// it whoever wrote it would instead open the fence to a sequencer that lost the role.
    async fn end_of_term(&self, term: u64, after: u64) -> Option<Option<(u64, Vec<u8>)>> {
        let last = match self.pool.stream.get_last_raw_message_by_subject(&self.pool.names.log).await {
            Ok(message) => message,
            Err(e) if after == 0 && (e.to_string().contains("no message") || e.to_string().contains("not found")) => {
                return Some(Some((0, Vec::new())));
            }
            Err(_) => return None,
        };
        let mine = last.sequence == after
            || protocol::read_tick(&last.payload, self.role.size).is_ok_and(|tick| tick.term == term);
        Some(mine.then(|| (last.sequence, last.payload.to_vec())))
    }

    /// Asks the game thread for its state and stores it as the latest snapshot.
    async fn store_snapshot(&self) {
        // An edge still joining has nothing to offer: it would replace a good snapshot.
        if !self.role.state.joined.load(Ordering::Relaxed) {
            return;
        }
        let (reply, answer) = oneshot::channel();
        if self.role.snapshots.send(Incoming::Snapshot(reply)).await.is_err() {
            return;
        }
        let Ok(bytes) = answer.await else { return };
        if bytes.len() > MAX_SNAPSHOT_BYTES {
            eprintln!("bus: snapshot of {} bytes not stored (at most {MAX_SNAPSHOT_BYTES})", bytes.len());
            return;
        }
        if let Err(e) = self.pool.snapshots.put(SNAPSHOT_OBJECT, &mut bytes.as_slice()).await {
            eprintln!("bus: snapshot not stored ({e})");
        }
    }
}

#[cfg(test)]
#[path = "lead_tests.rs"]
mod tests;
