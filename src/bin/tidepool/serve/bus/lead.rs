//! The async glue of the sequencer's role: every edge watches the lease; the one that holds
//! it reads the log's last tick, takes the players' requests, publishes a tick every
//! [`TICK_PERIOD`] (each publish fenced by the log's expected last sequence, so a sequencer
//! that lost the lease without knowing cannot write after the new one), refreshes the lease,
//! and stores its edge's snapshot every [`SNAPSHOT_PERIOD`].

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use async_nats::jetstream::context::PublishErrorKind;
use async_nats::jetstream::kv::Operation;
use async_nats::jetstream::message::PublishMessage;
use futures_util::StreamExt;
use tokio::sync::{mpsc, oneshot};
use tokio_util::sync::CancellationToken;

use super::edge::{BusState, Incoming};
use super::lease::{self, Lease, LeaseStep};
use super::link::{PoolLink, SNAPSHOT_OBJECT};
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

/// An edge's part in the sequencer's role.
pub struct Leader {
    /// The pool.
    pub pool: Arc<PoolLink>,
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

/// Why a sequencer stopped.
enum Ended {
    Stopped,
    LostLease,
}

impl Leader {
    /// Watches the lease until `stop`; sequences while it holds it.
    pub async fn run(self, stop: CancellationToken) {
        let mut lease = Lease::new(&self.me);
        while !stop.is_cancelled() {
            let entry = match self.pool.kv.entry(LEASE_KEY).await {
                Ok(entry) => entry.filter(|e| e.operation == Operation::Put),
                Err(_) => {
                    tokio::select! { _ = stop.cancelled() => return, _ = tokio::time::sleep(lease::POLL) => continue }
                }
            };
            let now = Instant::now();
            let holder = entry.as_ref().map(|e| (String::from_utf8_lossy(&e.value).into_owned(), e.revision));
            let wrote = match lease.observe(holder.as_ref().map(|(h, r)| (h.as_str(), *r)), now) {
                LeaseStep::Wait => None,
                LeaseStep::Create => Some(self.pool.kv.create(LEASE_KEY, self.me.clone().into()).await.ok()),
                LeaseStep::Update(r) => Some(self.pool.kv.update(LEASE_KEY, self.me.clone().into(), r).await.ok()),
            };
            match wrote {
                Some(Some(revision)) => lease.wrote(revision, Instant::now()),
                Some(None) => lease.refused(),
                None => {}
            }
            if lease.held().is_some() {
                if let Some(previous) = holder.filter(|(h, _)| *h != self.me) {
                    eprintln!("bus: took the sequencer's role over from {}", previous.0);
                }
                self.state.leading.store(true, Ordering::Relaxed);
                let ended = self.sequence(&mut lease, &stop).await;
                self.state.leading.store(false, Ordering::Relaxed);
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
        if let Ok(tick) = protocol::read_tick(&last.payload, self.size) {
            return Ok((end, Some(tick)));
        }
        for seq in (end.saturating_sub(LOOK_BACK)..end).rev().filter(|&s| s > 0) {
            if let Ok(message) = self.pool.stream.get_raw_message(seq).await
                && let Ok(tick) = protocol::read_tick(&message.payload, self.size)
            {
                return Ok((end, Some(tick)));
            }
        }
        Ok((end, None))
    }

    /// Sequences while the lease holds.
    async fn sequence(&self, lease: &mut Lease, stop: &CancellationToken) -> Ended {
        let Some(term) = lease.held() else { return Ended::LostLease };
        let (mut last_seq, last) = match self.last_tick().await {
            Ok(x) => x,
            Err(e) => {
                eprintln!("bus: cannot read the log's end ({e}); giving the role up");
                return Ended::LostLease;
            }
        };
        let now = Instant::now();
        let mut seq =
            Sequencer::new(self.size, self.steps_per_second, self.limits, self.seed, last.as_ref(), term, now);
        eprintln!("bus: this edge is the sequencer (term {term}), after log entry {last_seq}");
        let (Ok(mut submits), Ok(mut presence)) = (
            self.pool.client.subscribe(self.pool.names.submit.clone()).await,
            self.pool.client.subscribe(self.pool.names.presence.clone()).await,
        ) else {
            return Ended::LostLease;
        };
        let mut ticks = tokio::time::interval(TICK_PERIOD);
        let mut refresh = tokio::time::interval(lease::REFRESH);
        let mut snapshot = tokio::time::interval(SNAPSHOT_PERIOD);
        let mut refusals = Refusals::default();
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
                    match self.publish(&tick, last_seq).await {
                        Ok(s) => last_seq = s,
                        Err(Some(why)) => {
                            eprintln!("bus: {why}; giving the sequencer's role up");
                            return Ended::LostLease;
                        }
                        // The bus is away: this tick's events are lost (never acknowledged);
                        // the next tick carries on, after the log's end as it then stands.
                        Err(None) => {
                            if let Ok((s, _)) = self.last_tick().await {
                                last_seq = s;
                            }
                        }
                    }
                }
                _ = refresh.tick() => {
                    let Some(revision) = lease.held() else { return Ended::LostLease };
                    match self.pool.kv.update(LEASE_KEY, self.me.clone().into(), revision).await {
                        Ok(r) => lease.wrote(r, Instant::now()),
                        Err(e) if lease.expired(Instant::now()) => {
                            eprintln!("bus: cannot renew the lease ({e})");
                            lease.refused();
                            return Ended::LostLease;
                        }
                        Err(_) => {}
                    }
                }
                _ = snapshot.tick() => self.store_snapshot().await,
            }
        }
    }

    /// Publishes a tick after log entry `after`; its sequence, or why it failed: `Some` when
    /// another sequencer wrote since (this one lost the role), `None` when the bus is away.
    async fn publish(&self, tick: &Tick, after: u64) -> Result<u64, Option<String>> {
        let message = PublishMessage::build().payload(protocol::bytes_of(tick).into()).expected_last_sequence(after);
        let ack = self.pool.js.send_publish(self.pool.names.log.clone(), message).await.map_err(|_| None)?;
        match ack.await {
            Ok(ack) => Ok(ack.sequence),
            Err(e) if e.kind() == PublishErrorKind::WrongLastSequence => {
                Err(Some(format!("the log moved on after entry {after} without this sequencer")))
            }
            Err(_) => Err(None),
        }
    }

    /// Asks the game thread for its state and stores it as the latest snapshot.
    async fn store_snapshot(&self) {
        // An edge still joining has nothing to offer: it would replace a good snapshot.
        if !self.state.joined.load(Ordering::Relaxed) {
            return;
        }
        let (reply, answer) = oneshot::channel();
        if self.snapshots.send(Incoming::Snapshot(reply)).await.is_err() {
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
