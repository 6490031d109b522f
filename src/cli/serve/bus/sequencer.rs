//! The sequencer: one per pool, on whichever edge holds the lease. It takes every player's
//! [`Submit`], refuses what is malformed, out of bounds or over a limit (per player, per edge,
//! per pool), picks where random stones land, keeps the pool's clock (pause included), and
//! makes the next [`Tick`]: the step every edge may run to and the events they apply there.
//!
//! Sans-IO: bytes and `now` in, ticks out. The async glue (`lead.rs`) publishes the ticks.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use crate::output::bucket::ByteBucket;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::handled::{Handled, Verdict};
use super::protocol::{
    self, MAX_EVENTS_PER_TICK, MAX_SETTLED_PER_TICK, Refusal, RequestId, Stamped, Submit, Tick, Wire,
};

/// Steps between the sequencer's step and the step it stamps events at: an edge runs behind
/// by about this much, so a tick that comes this late still never stops it. At 60 steps a
/// second, 6 steps are 100 ms: two tick periods and a LAN's delivery.
pub const LEAD_STEPS: u64 = 6;
/// How often a tick is published (and so the longest an event waits for one).
pub const TICK_PERIOD: Duration = Duration::from_millis(33);
/// An edge's presence counts this long.
const PRESENCE_LIFETIME: Duration = Duration::from_secs(3);
/// Most edges the sequencer keeps track of.
pub const MAX_EDGES: usize = 256;
/// Most players whose buckets are kept; beyond it the quiet ones are forgotten first.
pub const MAX_TRACKED_PLAYERS: usize = 20_000;
/// A player quiet this long is forgotten (their buckets are full again by then, so forgetting
/// changes no verdict).
const PLAYER_FORGET: Duration = Duration::from_secs(10);
/// An edge heard from neither by presence nor by a request this long is forgotten (its bucket
/// is full again and its presence no longer counts).
const EDGE_FORGET: Duration = Duration::from_secs(10);
/// How often the quiet players, edges and runs are forgotten (a sweep of the tables).
const FORGET_EVERY: Duration = Duration::from_secs(1);
/// Events one edge may send a second, all its players together.
pub const EDGE_EVENTS_PER_SECOND: f64 = 3_000.0;
/// The burst every bucket allows.
const BURST: Duration = Duration::from_secs(1);
/// Seed mix of the random stones' spots (as the host's, so one seed gives one pool).
const STONE_SEED_MIX: u64 = 0x5354_4f4e_4553_0001;

/// The limits the sequencer applies.
#[derive(Clone, Copy, Debug)]
pub struct SequencerLimits {
    /// A player's stones and stirs a second.
    pub actions_per_second: f64,
    /// A player's scene keys a second.
    pub scene_keys_per_second: f64,
    /// All players' scene keys a second.
    pub pool_scene_keys_per_second: f64,
}

struct PlayerBuckets {
    actions: ByteBucket,
    scene_keys: ByteBucket,
    last: Instant,
}

struct EdgeSeen {
    events: ByteBucket,
    players: u32,
    /// Its last presence.
    last: Instant,
    /// Its last message of any kind.
    heard: Instant,
}

/// Counters for the log line and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SequencerCounts {
    /// Submits taken into the log.
    pub accepted: u64,
    /// Submits refused (malformed, out of bounds, over a limit).
    pub refused: u64,
    /// Ticks made.
    pub ticks: u64,
    /// Requests handled before in this term (sent again by their edge): ignored.
    pub duplicates: u64,
    /// Requests sent again by an edge that had not read the log up to this term: left for
    /// its next send (an earlier term may have stamped them).
    pub deferred: u64,
}

/// The pool's sequencer.
///
/// Its memory is bounded by the players and edges of the last seconds, not by how long it has
/// run nor by how many players ever came: every [`FORGET_EVERY`] it forgets the players quiet
/// for [`PLAYER_FORGET`], the edges quiet for [`EDGE_FORGET`] and the edges' runs quiet for a
/// minute (`handled.rs`); at most [`MAX_TRACKED_PLAYERS`] players, [`MAX_EDGES`] edges and 512
/// runs of at most 4,096 ids each at any time. Before, the quiet were forgotten only once a
/// table was full: a pool whose players come and go kept every player who ever pressed a key,
/// up to 20,000 (docs/serve/bus.md, round 6).
pub struct Sequencer {
    size: (u32, u32),
    limits: SequencerLimits,
    steps_per_second: f64,
    /// The clock: the step at `since`, and whether it runs.
    base: (u64, Instant),
    paused: bool,
    frontier: u64,
    term: u64,
    /// The log's last entry when this term began: what came before is earlier terms'.
    after: u64,
    events: Vec<Stamped>,
    /// Requests handled without an event (refused, or a pause) since the last tick.
    settled: Vec<RequestId>,
    handled: Handled,
    rng: ChaCha8Rng,
    players: HashMap<(String, u64), PlayerBuckets>,
    edges: HashMap<String, EdgeSeen>,
    pool_keys: ByteBucket,
    counts: SequencerCounts,
    /// When the quiet are next forgotten.
    next_forget: Instant,
}

impl Sequencer {
    /// A sequencer for a scene of `size` pixels at `steps_per_second`, taking over after
    /// `last` (the log's last tick; `None` for a new pool) with lease revision `term`, the
    /// log's last entry being `after`.
    #[allow(clippy::too_many_arguments)] // each is one fact of the term; a struct would only rename them
    pub fn new(
        size: (u32, u32),
        steps_per_second: f64,
        limits: SequencerLimits,
        seed: u64,
        last: Option<&Tick>,
        (term, after): (u64, u64),
        now: Instant,
    ) -> Sequencer {
        let (frontier, paused) = last.map_or((0, false), |t| (t.step, t.paused));
        Sequencer {
            size,
            limits,
            steps_per_second,
            // The clock goes on from where the edges stand: the last frontier, less the lead.
            base: (frontier.saturating_sub(LEAD_STEPS), now),
            paused,
            frontier,
            term,
            after,
            events: Vec::new(),
            settled: Vec::new(),
            handled: Handled::default(),
            rng: ChaCha8Rng::seed_from_u64(seed ^ STONE_SEED_MIX ^ term),
            players: HashMap::new(),
            edges: HashMap::new(),
            pool_keys: ByteBucket::limit(limits.pool_scene_keys_per_second, BURST),
            counts: SequencerCounts::default(),
            next_forget: now + FORGET_EVERY,
        }
    }

    /// The pool's step now by its clock.
    fn step(&self, now: Instant) -> u64 {
        if self.paused {
            return self.base.0;
        }
        let elapsed = now.saturating_duration_since(self.base.1).as_secs_f64();
        self.base.0 + (elapsed * self.steps_per_second) as u64
    }

    /// Takes a player's request, or says why not. A request handled before in this term is
    /// ignored, and one sent again by an edge that had not read the log up to this term is
    /// left for later (both `Ok`, counted apart).
    pub fn submit(&mut self, bytes: &[u8], now: Instant) -> Result<(), Refusal> {
        let submit = match protocol::parse_submit(bytes) {
            Ok(submit) => submit,
            Err(why) => {
                self.counts.refused += 1;
                return Err(why);
            }
        };
        match self.handled.check(&submit, now) {
            Verdict::New => {}
            Verdict::Duplicate => {
                self.counts.duplicates += 1;
                return Ok(());
            }
            Verdict::Full => {
                self.counts.refused += 1;
                return Err(Refusal("too many edges".into()));
            }
        }
        if submit.again && submit.seen < self.after {
            self.counts.deferred += 1;
            return Ok(());
        }
        let id = submit.id();
        let result = self.take(submit, now);
        self.handled.mark(&id);
        match result {
            Ok(true) => self.counts.accepted += 1,
            Ok(false) => {
                self.counts.accepted += 1;
                self.settle(id);
            }
            Err(_) => {
                self.counts.refused += 1;
                self.settle(id);
            }
        }
        result.map(|_| ())
    }

    /// Tells the request's edge, in the next tick, that it is handled without an event.
    fn settle(&mut self, id: RequestId) {
        if self.settled.len() < MAX_SETTLED_PER_TICK {
            self.settled.push(id);
        }
    }

    /// Takes a checked request: `Ok(true)` when it is an event of the next tick.
    fn take(&mut self, submit: Submit, now: Instant) -> Result<bool, Refusal> {
        submit.what.check(self.size)?;
        if self.events.len() >= MAX_EVENTS_PER_TICK {
            return Err(Refusal("the pool's events for this tick are full".into()));
        }
        self.forget_quiet(now);
        if !self.edges.contains_key(&submit.edge) && self.edges.len() >= MAX_EDGES {
            return Err(Refusal("too many edges".into()));
        }
        let edge = self.edges.entry(submit.edge.clone()).or_insert(EdgeSeen {
            events: ByteBucket::limit(EDGE_EVENTS_PER_SECOND, BURST),
            players: 0,
            last: now,
            heard: now,
        });
        edge.heard = now;
        if !edge.events.try_take(1.0, now) {
            return Err(Refusal(format!("edge {} is over {EDGE_EVENTS_PER_SECOND} events a second", submit.edge)));
        }
        let key = (submit.edge.clone(), submit.player);
        if !self.players.contains_key(&key) && self.players.len() >= MAX_TRACKED_PLAYERS {
            return Err(Refusal("too many players".into()));
        }
        let limits = self.limits;
        let player = self.players.entry(key).or_insert_with(|| PlayerBuckets {
            actions: ByteBucket::limit(limits.actions_per_second, BURST),
            scene_keys: ByteBucket::limit(limits.scene_keys_per_second, BURST),
            last: now,
        });
        player.last = now;
        // A request sent again is not charged to its player: its first send may have been,
        // by this term or the last, and a takeover's resends come in a burst. The edge's rate
        // and the pool's still hold (a player's rate never held against a hostile edge, which
        // may name as many players as it likes).
        let allowed = if submit.what.is_scene_key() {
            (submit.again || player.scene_keys.try_take(1.0, now)) && self.pool_keys.try_take(1.0, now)
        } else {
            submit.again || player.actions.try_take(1.0, now)
        };
        if !allowed {
            return Err(Refusal(format!("player {}/{} is over a rate", submit.edge, submit.player)));
        }
        let what = match submit.what {
            Wire::RandomStone { radius } => {
                let (w, h) = self.size;
                Wire::stone_at(self.rng.random_range(0..w) as i32, self.rng.random_range(0..h) as i32, radius)
            }
            Wire::Pause => {
                let step = self.step(now);
                self.paused = !self.paused;
                self.base = (step, now);
                return Ok(false);
            }
            other => other,
        };
        self.events.push(Stamped { what, edge: submit.edge, run: submit.run, n: submit.n });
        Ok(true)
    }

    /// A tick of this term that never reached the log: its events did not happen, so their
    /// ids are forgotten (their edges send them again and they are taken then); what it
    /// settled stays settled (a pause toggled the clock all the same) and is told again.
    pub fn forget(&mut self, tick: &Tick) {
        for e in &tick.events {
            self.handled.forget(&RequestId { edge: e.edge.clone(), run: e.run, n: e.n });
        }
        for id in &tick.settled {
            self.settle(id.clone());
        }
    }

    /// Notes an edge's player count.
    pub fn presence(&mut self, bytes: &[u8], now: Instant) -> Result<(), Refusal> {
        let p = protocol::read_presence(bytes)?;
        if !self.edges.contains_key(&p.edge) && self.edges.len() >= MAX_EDGES {
            self.forget_quiet(now);
            if self.edges.len() >= MAX_EDGES {
                return Err(Refusal("too many edges".into()));
            }
        }
        let edge = self.edges.entry(p.edge).or_insert(EdgeSeen {
            events: ByteBucket::limit(EDGE_EVENTS_PER_SECOND, BURST),
            players: 0,
            last: now,
            heard: now,
        });
        edge.players = p.players;
        (edge.last, edge.heard) = (now, now);
        Ok(())
    }

    /// Forgets the players and edges nobody heard from lately, when their tables are full.
    fn forget_quiet(&mut self, now: Instant) {
        if self.players.len() >= MAX_TRACKED_PLAYERS {
            self.players.retain(|_, p| now.saturating_duration_since(p.last) < PLAYER_FORGET);
        }
        if self.edges.len() >= MAX_EDGES {
            self.edges.retain(|_, e| now.saturating_duration_since(e.last) < PRESENCE_LIFETIME);
        }
    }

    /// Forgets, every [`FORGET_EVERY`], the players, edges and runs quiet long enough that
    /// remembering them changes no verdict (their buckets full again; their runs' requests
    /// given up by their edges).
    fn forget_old(&mut self, now: Instant) {
        if now < self.next_forget {
            return;
        }
        self.next_forget = now + FORGET_EVERY;
        self.players.retain(|_, p| now.saturating_duration_since(p.last) < PLAYER_FORGET);
        self.edges.retain(|_, e| now.saturating_duration_since(e.heard) < EDGE_FORGET);
        self.handled.forget_quiet(now);
    }

    /// Players, edges and runs remembered, and the ids of the runs (for the memory's test).
    #[cfg(test)]
    pub fn kept(&self) -> (usize, usize, usize, usize) {
        (self.players.len(), self.edges.len(), self.handled.runs(), self.handled.len())
    }

    /// The next tick: the frontier moved up to the clock's step plus the lead, and the events
    /// taken since the last tick stamped at it.
    pub fn tick(&mut self, now: Instant) -> Tick {
        self.forget_old(now);
        self.frontier = self.frontier.max(self.step(now) + LEAD_STEPS);
        self.counts.ticks += 1;
        let players = self
            .edges
            .values()
            .filter(|e| now.saturating_duration_since(e.last) < PRESENCE_LIFETIME)
            .map(|e| e.players)
            .fold(0u32, u32::saturating_add);
        Tick {
            step: self.frontier,
            term: self.term,
            paused: self.paused,
            players,
            events: std::mem::take(&mut self.events),
            settled: std::mem::take(&mut self.settled),
        }
    }

    /// What it did so far.
    pub fn counts(&self) -> SequencerCounts {
        self.counts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::serve::bus::protocol::{Submit, bytes_of};

    const LIMITS: SequencerLimits =
        SequencerLimits { actions_per_second: 30.0, scene_keys_per_second: 4.0, pool_scene_keys_per_second: 8.0 };

    fn sequencer(now: Instant) -> Sequencer {
        Sequencer::new((160, 90), 60.0, LIMITS, 1, None, (1, 0), now)
    }

    fn submit(edge: &str, player: u64, what: Wire) -> Vec<u8> {
        // Each its own id: the sequencer stamps an id once.
        static N: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        bytes_of(&Submit::new(edge, player, N.fetch_add(1, std::sync::atomic::Ordering::Relaxed), what))
    }

    #[test]
    fn events_are_stamped_ahead_of_the_clock_and_the_frontier_never_goes_back() {
        let t0 = Instant::now();
        let mut s = sequencer(t0);
        s.submit(&submit("a", 1, Wire::Clear), t0).unwrap();
        let first = s.tick(t0);
        assert_eq!((first.step, first.events.len()), (LEAD_STEPS, 1));
        let later = s.tick(t0 + Duration::from_secs(1));
        assert_eq!((later.step, later.events.len()), (60 + LEAD_STEPS, 0));
        // A sequencer taking over goes on from the last frontier.
        let next = Sequencer::new((160, 90), 60.0, LIMITS, 1, Some(&later), (2, 2), t0).tick(t0);
        assert_eq!((next.step, next.term), (later.step, 2));
    }

    #[test]
    fn random_stones_are_resolved_and_pause_stops_the_frontier() {
        let t0 = Instant::now();
        let mut s = sequencer(t0);
        s.submit(&submit("a", 1, Wire::RandomStone { radius: 3 }), t0).unwrap();
        s.submit(&submit("a", 1, Wire::Pause), t0).unwrap();
        let tick = s.tick(t0);
        assert!(matches!(tick.events[0].what, Wire::Stone { radius: 3, .. }), "{tick:?}");
        assert_eq!(tick.events.len(), 1);
        assert!(tick.paused);
        assert_eq!(s.tick(t0 + Duration::from_secs(5)).step, tick.step);
    }

    #[test]
    fn limits_hold_per_player_and_per_pool() {
        let t0 = Instant::now();
        let mut s = sequencer(t0);
        // A second's burst of stones at 30 a second, then refusals; another player is not hit.
        let taken = (0..40).filter(|_| s.submit(&submit("a", 1, Wire::stone_at(5, 5, 2)), t0).is_ok()).count();
        assert_eq!(taken, 30);
        assert!(s.submit(&submit("a", 2, Wire::stone_at(1, 1, 1)), t0).is_ok());
        // Scene keys: 4 for one player, 8 for the pool.
        let keys = (0..10).filter(|_| s.submit(&submit("b", 1, Wire::Rain), t0).is_ok()).count();
        assert_eq!(keys, 4);
        let all = (2..10).filter(|&p| s.submit(&submit("b", p, Wire::Rain), t0).is_ok()).count();
        assert_eq!(all, 4);
        assert_eq!(s.counts().refused, 10 + 6 + 4);
    }

    #[test]
    fn malformed_and_out_of_bounds_submits_are_refused_with_a_reason() {
        let t0 = Instant::now();
        let mut s = sequencer(t0);
        let why = s.submit(&submit("a", 1, Wire::stone_at(500, 1, 2)), t0).unwrap_err();
        assert!(why.0.contains("outside"), "{why}");
        assert!(s.submit(b"\xff\xfe", t0).is_err());
        assert_eq!(s.tick(t0).events, vec![]);
        assert_eq!(s.counts(), SequencerCounts { accepted: 0, refused: 2, ticks: 1, ..SequencerCounts::default() });
    }

    #[test]
    fn presence_adds_up_the_pool() {
        let t0 = Instant::now();
        let mut s = sequencer(t0);
        s.presence(&bytes_of(&protocol::Presence { edge: "a".into(), players: 3 }), t0).unwrap();
        s.presence(&bytes_of(&protocol::Presence { edge: "b".into(), players: 4 }), t0).unwrap();
        assert_eq!(s.tick(t0).players, 7);
        assert_eq!(s.tick(t0 + PRESENCE_LIFETIME).players, 0);
    }
}
