//! An edge's copy of the pool, run from the log: every tick says how far the scene may run
//! and which events apply at which step, and every edge applies the same events at the same
//! steps through the same `Scene::apply`, so step N is the same water (and the same picture)
//! everywhere, as a replay is the session it recorded.
//!
//! The edge follows the sequencer's clock as it sees it: the last tick's step less the lead,
//! plus the time since that tick came, never past the tick's step. A tick that comes late
//! only stops the water if it is later than the lead.
//!
//! Sans-IO: ticks (bytes with their log sequence) and `now` in; the scene, a snapshot's bytes
//! and the screenshot steps out.

use std::collections::VecDeque;
use std::time::Instant;

use crate::{Controls, PoolScene, Scene};

use super::protocol::{self, MAX_EVENTS_PER_TICK, Refusal, Stamped, Wire};
use super::sequencer::LEAD_STEPS;

/// The first bytes of an edge's snapshot.
const MAGIC: &[u8; 6] = b"TPBUS1";
/// The largest snapshot an edge writes or reads (a 640x360 pool on grid 4 is about 15 MB).
pub const MAX_SNAPSHOT_BYTES: usize = 16 << 20;
/// Most events waiting for their step (a tick holds at most [`MAX_EVENTS_PER_TICK`]; ticks
/// run ahead of the edge by the lead, a few ticks).
const MAX_PENDING: usize = 16 * MAX_EVENTS_PER_TICK;

/// What a tick did not do.
#[derive(Debug, PartialEq, Eq)]
pub enum Missed {
    /// A log entry is missing between the last one and this: the edge must join again.
    Gap {
        /// The sequence expected.
        expected: u64,
        /// The one that came.
        got: u64,
    },
    /// The entry is not a tick (every edge skips it alike).
    Bad(Refusal),
}

/// The pool as this edge runs it.
pub struct Lockstep {
    scene: PoolScene,
    size: (u32, u32),
    step: u64,
    frontier: u64,
    last_seq: u64,
    paused: bool,
    players: u32,
    pending: VecDeque<(u64, Stamped)>,
    /// The sequencer's step as of the last tick, and when it came.
    anchor: Option<(u64, Instant)>,
}

impl Lockstep {
    /// A new pool's scene at step 0, before the log's first entry.
    pub fn new(scene: PoolScene) -> Lockstep {
        let size = (scene.width(), scene.height());
        Lockstep {
            scene,
            size,
            step: 0,
            frontier: 0,
            last_seq: 0,
            paused: false,
            players: 0,
            pending: VecDeque::new(),
            anchor: None,
        }
    }

    /// The step the scene shows.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// The log sequence of the last tick taken.
    pub fn last_seq(&self) -> u64 {
        self.last_seq
    }

    /// Players on the whole pool, as of the last tick.
    pub fn players(&self) -> u32 {
        self.players
    }

    /// Whether the pool's clock is paused.
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// The scene (to draw it and to say its status).
    pub fn scene_mut(&mut self) -> &mut PoolScene {
        &mut self.scene
    }

    /// Takes log entry `seq`.
    pub fn receive(&mut self, seq: u64, bytes: &[u8], now: Instant) -> Result<(), Missed> {
        if seq <= self.last_seq {
            return Ok(()); // delivered again after a reconnect: already taken
        }
        if seq != self.last_seq + 1 {
            return Err(Missed::Gap { expected: self.last_seq + 1, got: seq });
        }
        self.last_seq = seq;
        let tick = protocol::read_tick(bytes, self.size).map_err(Missed::Bad)?;
        if self.pending.len() + tick.events.len() > MAX_PENDING {
            return Err(Missed::Bad(Refusal("more events waiting than an edge keeps".into())));
        }
        // A tick's step is never behind the last one's; if one were (a sequencer that could
        // not read the log's end), its events apply at the frontier: a step every edge agrees
        // on, as it follows from the log alone.
        let stamp = tick.step.max(self.frontier);
        self.frontier = stamp;
        self.paused = tick.paused;
        self.players = tick.players;
        self.pending.extend(tick.events.into_iter().map(|e| (stamp, e)));
        self.anchor = Some((tick.step.saturating_sub(LEAD_STEPS), now));
        Ok(())
    }

    /// The step to be at by `now`: the sequencer's clock as seen, within the frontier.
    fn target(&self, now: Instant) -> u64 {
        let Some((base, at)) = self.anchor else { return self.step };
        if self.paused {
            return self.frontier;
        }
        let sps = self.scene.steps_per_second();
        let ahead = (now.saturating_duration_since(at).as_secs_f64() * sps) as u64;
        (base + ahead).min(self.frontier)
    }

    /// Runs the scene to where it should be by `now`, applying each event at its step;
    /// `shot(step, scene)` is called at each screenshot's step. Returns the steps run.
    pub fn run(&mut self, now: Instant, shot: &mut dyn FnMut(u64, &mut PoolScene)) -> u64 {
        let target = self.target(now);
        let start = self.step;
        loop {
            while self.pending.front().is_some_and(|(s, _)| *s <= self.step) {
                let Some((_, event)) = self.pending.pop_front() else { break };
                self.apply(&event, shot);
            }
            if self.step >= target {
                break;
            }
            let next = self.pending.front().map_or(target, |(s, _)| (*s).min(target));
            Scene::advance(&mut self.scene, next - self.step);
            self.step = next;
        }
        self.step - start
    }

    fn apply(&mut self, event: &Stamped, shot: &mut dyn FnMut(u64, &mut PoolScene)) {
        if event.what == Wire::Shot {
            shot(self.step, &mut self.scene);
            return;
        }
        if let Some(action) = event.what.action() {
            for e in self.scene.resolve(action) {
                self.scene.apply(&e);
            }
        }
    }

    /// The edge's state as bytes: where it is in the log, the events waiting, the pool.
    pub fn snapshot(&self) -> Vec<u8> {
        let pending: Vec<&(u64, Stamped)> = self.pending.iter().collect();
        let pending = protocol::bytes_of(&pending);
        let state = self.scene.save_state();
        let mut out = Vec::with_capacity(64 + pending.len() + state.len());
        out.extend_from_slice(MAGIC);
        for v in [self.step, self.frontier, self.last_seq, u64::from(self.paused), pending.len() as u64] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&pending);
        out.extend_from_slice(&state);
        out
    }

    /// Carries on from a snapshot (of a pool with the same settings); the log follows from
    /// the entry after [`Lockstep::last_seq`]. On an error nothing changes.
    pub fn restore(&mut self, bytes: &[u8], now: Instant) -> Result<(), Refusal> {
        let bad = |why: &str| Refusal(format!("snapshot: {why}"));
        if bytes.len() > MAX_SNAPSHOT_BYTES || bytes.len() < MAGIC.len() + 40 || &bytes[..MAGIC.len()] != MAGIC {
            return Err(bad("not an edge snapshot"));
        }
        let word = |i: usize| {
            let at = MAGIC.len() + 8 * i;
            u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or_default())
        };
        let (step, frontier, last_seq, paused, len) = (word(0), word(1), word(2), word(3) != 0, word(4));
        let rest = &bytes[MAGIC.len() + 40..];
        if len > rest.len() as u64 {
            return Err(bad("cut short"));
        }
        let (pending, state) = rest.split_at(len as usize);
        let pending: Vec<(u64, Stamped)> =
            serde_json::from_slice(pending).map_err(|e| bad(&format!("events waiting: {e}")))?;
        if pending.len() > MAX_PENDING || pending.iter().any(|(_, e)| e.what.check(self.size).is_err()) {
            return Err(bad("events waiting out of bounds"));
        }
        self.scene.restore_state(state).map_err(|e| bad(&e.to_string()))?;
        self.step = step;
        self.frontier = frontier.max(step);
        self.last_seq = last_seq;
        self.paused = paused;
        self.pending = pending.into();
        self.anchor = Some((step, now));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PoolSettings;
    use crate::cli::serve::bus::protocol::{Tick, bytes_of};
    use std::time::Duration;
    use tiny_skia::Pixmap;

    fn pool() -> PoolScene {
        let settings = PoolSettings { rain_rate: 0.2, seed: 3, ..PoolSettings::default() };
        PoolScene::new(48, 27, settings).unwrap()
    }

    fn tick(step: u64, events: &[Wire]) -> Vec<u8> {
        let events = events.iter().map(|&what| Stamped { what, edge: "a".into(), run: 0, n: 0 }).collect();
        bytes_of(&Tick { step, events, ..Tick::default() })
    }

    fn picture(l: &mut Lockstep) -> Vec<u8> {
        let mut out = Pixmap::new(48, 27).unwrap();
        PoolScene::render(l.scene_mut(), &mut out);
        out.data().to_vec()
    }

    fn none() -> impl FnMut(u64, &mut PoolScene) {
        |_, _| {}
    }

    /// Two edges fed the same log at different moments show the same water at the same step,
    /// and a third that joins from the first's snapshot midway does too.
    #[test]
    fn edges_fed_the_same_log_agree_bit_for_bit() {
        let t0 = Instant::now();
        let log = [
            tick(10, &[Wire::stone_at(10, 10, 3)]),
            tick(12, &[Wire::Rain, Wire::stone_at(30, 5, 2)]),
            tick(40, &[Wire::Stir { from: [1, 1], to: [20, 20] }]),
            tick(90, &[]),
        ];
        let (mut a, mut b, mut c) = (Lockstep::new(pool()), Lockstep::new(pool()), Lockstep::new(pool()));
        for (i, entry) in log.iter().enumerate() {
            a.receive(i as u64 + 1, entry, t0).unwrap();
            a.run(t0 + Duration::from_secs(9), &mut none());
            if i == 1 {
                c.restore(&a.snapshot(), t0).unwrap();
            } else if i > 1 {
                c.receive(i as u64 + 1, entry, t0).unwrap();
            }
        }
        for (i, entry) in log.iter().enumerate() {
            b.receive(i as u64 + 1, entry, t0).unwrap();
        }
        // b runs in small pieces of time, a and c in one.
        for ms in (0..3000).step_by(7) {
            b.run(t0 + Duration::from_millis(ms), &mut none());
        }
        c.run(t0 + Duration::from_secs(9), &mut none());
        assert_eq!((a.step(), b.step(), c.step()), (90, 90, 90));
        let pa = picture(&mut a);
        assert_eq!(pa, picture(&mut b));
        assert_eq!(pa, picture(&mut c));
        // The events mattered: an edge that missed one differs.
        let mut d = Lockstep::new(pool());
        d.receive(1, &tick(90, &[]), t0).unwrap();
        d.run(t0 + Duration::from_secs(9), &mut none());
        assert_ne!(pa, picture(&mut d));
    }

    #[test]
    fn the_edge_follows_the_clock_within_the_frontier() {
        let t0 = Instant::now();
        let mut a = Lockstep::new(pool());
        a.receive(1, &tick(100, &[]), t0).unwrap();
        // The sequencer was at 100 - LEAD when the tick came; 50 ms later, 3 steps more.
        assert_eq!(a.run(t0 + Duration::from_millis(50), &mut none()), 100 - LEAD_STEPS + 3);
        // Never past the frontier, however late.
        assert_eq!(a.run(t0 + Duration::from_secs(60), &mut none()), LEAD_STEPS - 3);
        assert_eq!(a.step(), 100);
    }

    #[test]
    fn screenshots_are_taken_at_their_step_and_gaps_are_found() {
        let t0 = Instant::now();
        let mut a = Lockstep::new(pool());
        a.receive(1, &tick(20, &[Wire::Shot]), t0).unwrap();
        let mut shots = Vec::new();
        a.run(t0 + Duration::from_secs(1), &mut |step, _| shots.push(step));
        assert_eq!(shots, vec![20]);
        assert_eq!(a.receive(3, &tick(30, &[]), t0), Err(Missed::Gap { expected: 2, got: 3 }));
        assert!(matches!(a.receive(2, b"{}", t0), Err(Missed::Bad(_))));
        // The bad entry is skipped like a good one: the next one follows.
        assert_eq!(a.receive(3, &tick(30, &[]), t0), Ok(()));
    }

    #[test]
    fn bad_snapshots_are_refused() {
        let t0 = Instant::now();
        let mut a = Lockstep::new(pool());
        let good = a.snapshot();
        for bad in [&good[..10], &good[..good.len() - 1], b"TPBUS1"] {
            assert!(a.restore(bad, t0).is_err());
        }
        assert!(a.restore(&good, t0).is_ok());
    }
}
