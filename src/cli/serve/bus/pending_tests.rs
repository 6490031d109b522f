//! The edge's pending requests against the sequencer's memory of what it handled, without
//! NATS: a simulated bus that loses what nobody listens to, sequencers that die with a tick
//! unread or never written, and edges that lag behind the log.

use super::*;
use crate::cli::serve::bus::sequencer::{Sequencer, SequencerLimits};

const LIMITS: SequencerLimits =
    SequencerLimits { actions_per_second: 1000.0, scene_keys_per_second: 100.0, pool_scene_keys_per_second: 100.0 };

/// The log and a sequencer that may be there or not.
struct Bus {
    log: Vec<Tick>,
    sequencer: Option<Sequencer>,
}

impl Bus {
    fn new(t0: Instant) -> Bus {
        Bus { log: Vec::new(), sequencer: Some(new_term(1, 0, t0)) }
    }

    /// Plain NATS: nobody listening, the message is lost.
    fn publish(&mut self, bytes: Vec<u8>, now: Instant) {
        if let Some(s) = &mut self.sequencer {
            let _ = s.submit(&bytes, now);
        }
    }

    /// The sequencer's tick, written to the log.
    fn tick(&mut self, now: Instant) {
        let tick = self.sequencer.as_mut().unwrap().tick(now);
        self.log.push(tick);
    }

    /// Another edge takes the role after the log's end.
    fn take_over(&mut self, term: u64, now: Instant) {
        self.sequencer = Some(new_term(term, self.log.len() as u64, now));
    }

    /// How often each of `edge`'s counts is in the log.
    fn stamped(&self, n: u64) -> usize {
        self.log.iter().flat_map(|t| &t.events).filter(|e| e.n == n && e.edge == "b").count()
    }
}

fn new_term(term: u64, after: u64, now: Instant) -> Sequencer {
    Sequencer::new((160, 90), 60.0, LIMITS, 7, None, (term, after), now)
}

/// The edge reads the log up to entry `to` (1-based).
fn read(edge: &mut Pending, bus: &Bus, from: &mut usize, to: usize) {
    while *from < to {
        edge.taken(*from as u64 + 1, &bus.log[*from]);
        *from += 1;
    }
}

fn stone(i: i32) -> Wire {
    Wire::stone_at(i, i, 2)
}

#[test]
fn every_request_is_stamped_once_through_a_takeover_a_lost_tick_and_a_lagging_edge() {
    let t0 = Instant::now();
    let at = |ms: u64| t0 + Duration::from_millis(ms);
    let mut bus = Bus::new(t0);
    let mut b = Pending::new("b", 1);
    let mut read_to = 0;
    // 1-5 stamped and read.
    for i in 1..=5 {
        let bytes = b.send(1, stone(i), t0);
        bus.publish(bytes, t0);
    }
    bus.tick(t0);
    read(&mut b, &bus, &mut read_to, 1);
    assert_eq!(b.len(), 0);
    // 6-10 stamped by sequencer 1 into entry 2, which b has not read when it dies.
    for i in 6..=10 {
        let bytes = b.send(1, stone(i), at(10));
        bus.publish(bytes, at(10));
    }
    bus.tick(at(33));
    bus.sequencer = None;
    // 11-15 sent while nobody listens: lost on the way.
    for i in 11..=15 {
        let bytes = b.send(1, stone(i), at(100));
        bus.publish(bytes, at(100));
    }
    // b, still behind, sends 6-15 again by its clock: the new sequencer cannot know whether
    // the old one stamped them, and leaves them.
    bus.take_over(2, at(1200));
    for bytes in b.due(at(2100)) {
        bus.publish(bytes, at(2100));
    }
    bus.tick(at(2133));
    assert_eq!(bus.log[2].events, vec![], "nothing taken from an edge that had not read entry 2");
    // b reads on: 6-10 are in entry 2; the new term makes 11-15 due at once.
    read(&mut b, &bus, &mut read_to, 3);
    let again = b.due(at(2140));
    assert_eq!(again.len(), 5);
    for bytes in again {
        bus.publish(bytes, at(2140));
    }
    // A tick of the new sequencer never reaches the log (the bus went away as it wrote).
    let lost = bus.sequencer.as_mut().unwrap().tick(at(2166));
    assert_eq!(lost.events.len(), 5);
    bus.sequencer.as_mut().unwrap().forget(&lost);
    // 16 is stamped into entry 4, which b reads late: its clock sends 11-16 again meanwhile.
    let bytes = b.send(1, stone(16), at(2200));
    bus.publish(bytes, at(2200));
    bus.tick(at(2233));
    for bytes in b.due(at(4200)) {
        bus.publish(bytes, at(4200));
    }
    bus.tick(at(4233));
    read(&mut b, &bus, &mut read_to, 5);
    assert_eq!(b.len(), 0, "every request in the log");
    for n in 1..=16 {
        assert_eq!(bus.stamped(n), 1, "request {n} in the log once: {:?}", bus.log);
    }
    assert_eq!(b.counts().dropped_old + b.counts().dropped_full, 0);
}

#[test]
fn refused_requests_and_pauses_are_settled_and_a_pause_toggles_once() {
    let t0 = Instant::now();
    let mut bus = Bus::new(t0);
    let mut b = Pending::new("b", 1);
    let bytes = b.send(1, Wire::Pause, t0);
    bus.publish(bytes.clone(), t0);
    let bytes = b.send(1, Wire::stone_at(500, 1, 2), t0);
    assert!(bus.sequencer.as_mut().unwrap().submit(&bytes, t0).is_err(), "outside the pool");
    bus.tick(t0);
    assert!(bus.log[0].paused);
    assert_eq!(bus.log[0].settled.len(), 2);
    // Sent again before b read the tick: still paused, not toggled back.
    for bytes in b.due(t0 + RESEND_AFTER) {
        bus.publish(bytes, t0 + RESEND_AFTER);
    }
    bus.tick(t0 + RESEND_AFTER);
    assert!(bus.log[1].paused);
    let mut read_to = 0;
    read(&mut b, &bus, &mut read_to, 2);
    assert_eq!(b.len(), 0);
}

#[test]
fn the_queue_is_bounded_in_count_age_and_resend_rate() {
    let t0 = Instant::now();
    let mut b = Pending::new("b", 1);
    for i in 0..MAX_WAITING as i32 + 3 {
        b.send(1, stone(i % 100), t0);
    }
    assert_eq!((b.len(), b.counts().dropped_full), (MAX_WAITING, 3));
    // A new term: everything due at once, within the resend rate's burst.
    b.taken(1, &Tick { term: 5, ..Tick::default() });
    assert_eq!(b.due(t0).len(), RESENDS_PER_SECOND as usize);
    assert_eq!(b.due(t0 + Duration::from_millis(100)).len(), MAX_WAITING - RESENDS_PER_SECOND as usize);
    // Nothing more until RESEND_AFTER; all given up at MAX_AGE.
    assert_eq!(b.due(t0 + Duration::from_millis(200)).len(), 0);
    assert!(b.due(t0 + MAX_AGE).is_empty());
    assert_eq!((b.len(), b.counts().dropped_old), (0, MAX_WAITING as u64));
}
