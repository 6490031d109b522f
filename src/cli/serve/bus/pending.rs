//! The edge's requests until the log has them: every request a player makes is kept here,
//! under the id `(edge, run, n)`, until a tick names it (as an event, or as settled: refused or
//! a pause), and sent again meanwhile: at once when the log shows a new sequencer's term (the
//! old one may have died with it), and after [`RESEND_AFTER`] otherwise (lost on the way, or
//! in a tick that never reached the log). The sequencer stamps an id once (`handled.rs`), so a
//! stone sent twice is applied once. Sans-IO: requests, ticks and `now` in, bytes out.
//!
//! Bounded: at most [`MAX_WAITING`] requests for at most [`MAX_AGE`] each (past either, the
//! oldest is given up and counted, for the edge's log), sent again at most
//! [`RESENDS_PER_SECOND`].

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use crate::output::bucket::ByteBucket;

use super::protocol::{self, Submit, Tick, Wire};

/// Requests kept at most (a player's rate is 30 a second; 512 is a crowd's half second).
pub const MAX_WAITING: usize = 512;
/// The longest a request is kept: a takeover takes 1 to 1.5 s, a restart of nats-server a few.
pub const MAX_AGE: Duration = Duration::from_secs(10);
/// A request not in the log this long is sent again (a tick comes every 33 ms; the p95 of a
/// request's trip to the log was 0.5 s on an overloaded machine, docs/serve/bus.md).
pub const RESEND_AFTER: Duration = Duration::from_secs(2);
/// Sends again a second at most (within the sequencer's 3,000 events a second an edge), with
/// a second's burst: a full queue on a new term goes out within two seconds.
pub const RESENDS_PER_SECOND: f64 = 500.0;

struct Waiting {
    n: u64,
    player: u64,
    what: Wire,
    first: Instant,
    sent: Instant,
    /// A new term came since it was sent: send it again at once.
    due: bool,
}

/// What became of the requests, for the edge's log.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PendingCounts {
    /// Sent for the first time.
    pub sent: u64,
    /// Sent again.
    pub resent: u64,
    /// Found in the log.
    pub settled: u64,
    /// Given up because [`MAX_WAITING`] were waiting.
    pub dropped_full: u64,
    /// Given up after [`MAX_AGE`].
    pub dropped_old: u64,
    /// Given up because the edge joined again from a snapshot (it cannot tell which of them
    /// the entries it skipped held).
    pub dropped_rejoin: u64,
}

/// An edge's requests not yet in the log.
pub struct Pending {
    edge: String,
    run: u64,
    /// The last count used.
    last: u64,
    waiting: VecDeque<Waiting>,
    term: u64,
    seen: u64,
    resends: ByteBucket,
    counts: PendingCounts,
}

impl Pending {
    /// The requests of `edge` in its run `run` (a number no earlier run of the same name used).
    pub fn new(edge: &str, run: u64) -> Pending {
        Pending {
            edge: edge.to_owned(),
            run,
            last: 0,
            waiting: VecDeque::new(),
            term: 0,
            seen: 0,
            resends: ByteBucket::limit(RESENDS_PER_SECOND, Duration::from_secs(1)),
            counts: PendingCounts::default(),
        }
    }

    /// Keeps a player's request and returns its bytes to send; the oldest kept is given up if
    /// [`MAX_WAITING`] are.
    pub fn send(&mut self, player: u64, what: Wire, now: Instant) -> Vec<u8> {
        if self.waiting.len() >= MAX_WAITING {
            self.waiting.pop_front();
            self.counts.dropped_full += 1;
        }
        self.last += 1;
        self.counts.sent += 1;
        self.waiting.push_back(Waiting { n: self.last, player, what, first: now, sent: now, due: false });
        let w = &self.waiting[self.waiting.len() - 1];
        self.bytes(w, false)
    }

    /// The count of the last request (the trace's `sent` line names it).
    pub fn last(&self) -> u64 {
        self.last
    }

    fn bytes(&self, w: &Waiting, again: bool) -> Vec<u8> {
        let floor = self.waiting.front().map_or(self.last + 1, |f| f.n);
        protocol::bytes_of(&Submit {
            edge: self.edge.clone(),
            run: self.run,
            player: w.player,
            n: w.n,
            floor,
            seen: self.seen,
            again,
            what: w.what,
        })
    }

    fn mine(&self, edge: &str, run: u64) -> bool {
        run == self.run && edge == self.edge
    }

    /// Takes log entry `seq` (its tick `tick`): its requests of this edge are settled; a new
    /// term makes every request still kept due at once.
    pub fn taken(&mut self, seq: u64, tick: &Tick) {
        self.seen = self.seen.max(seq);
        let ids = tick.events.iter().map(|e| (e.edge.as_str(), e.run, e.n));
        for (edge, run, n) in ids.chain(tick.settled.iter().map(|i| (i.edge.as_str(), i.run, i.n))) {
            if !self.mine(edge, run) {
                continue;
            }
            if let Ok(at) = self.waiting.binary_search_by_key(&n, |w| w.n) {
                self.waiting.remove(at);
                self.counts.settled += 1;
            }
        }
        if tick.term > self.term {
            self.term = tick.term;
            for w in &mut self.waiting {
                w.due = true;
            }
        }
    }

    /// The edge joined again from a snapshot: what it kept is given up (the entries the
    /// snapshot stands for may hold some of it, and the edge never read them).
    pub fn rejoined(&mut self, seq: u64) {
        self.counts.dropped_rejoin += self.waiting.len() as u64;
        self.waiting.clear();
        self.seen = self.seen.max(seq);
    }

    /// Gives up what is too old and returns what is due to be sent again (at most the resend
    /// rate allows), oldest first.
    pub fn due(&mut self, now: Instant) -> Vec<Vec<u8>> {
        while self.waiting.front().is_some_and(|w| now.saturating_duration_since(w.first) >= MAX_AGE) {
            self.waiting.pop_front();
            self.counts.dropped_old += 1;
        }
        let mut out = Vec::new();
        for i in 0..self.waiting.len() {
            let w = &self.waiting[i];
            if !w.due && now.saturating_duration_since(w.sent) < RESEND_AFTER {
                continue;
            }
            if !self.resends.try_take(1.0, now) {
                break;
            }
            out.push(self.bytes(w, true));
            let w = &mut self.waiting[i];
            (w.sent, w.due) = (now, false);
            self.counts.resent += 1;
        }
        out
    }

    /// Requests kept now.
    pub fn len(&self) -> usize {
        self.waiting.len()
    }

    /// What became of them so far.
    pub fn counts(&self) -> PendingCounts {
        self.counts
    }
}

#[cfg(test)]
#[path = "pending_tests.rs"]
mod tests;
