//! The sequencer's memory of the requests it handled in its term (stamped into a tick, refused,
//! or taken into the clock as a pause), so that a request an edge sends again is handled once
//! and a stone is applied once (`bus/pending.rs` is the edge's half). Sans-IO.
//!
//! Bounded three ways: per run of an edge, the ids below the floor the edge reports (every
//! request below it is settled for the edge) are forgotten, and at most
//! [`MAX_IDS_PER_RUN`] are kept (past it the oldest go and the floor rises: a request older
//! than that is taken for handled); at most [`MAX_RUNS`] runs are kept, and a run quiet for
//! [`RUN_FORGET`] is forgotten (every second, by [`Handled::forget_quiet`]; and at once when
//! the table is full).

use std::collections::{BTreeSet, HashMap};
use std::time::{Duration, Instant};

use super::protocol::{RequestId, Submit};

/// Ids kept for one run of an edge. The edge keeps at most 512 requests for at most 10 s
/// (`pending.rs`); an id stays here from its stamp until the edge's floor passes it, which a
/// fast edge (3,000 requests a second, the sequencer's bound) moves within a few ticks.
pub const MAX_IDS_PER_RUN: usize = 4096;
/// Runs kept: twice the sequencer's 256 edges (an edge restarted gets a new run; the old one
/// goes quiet).
pub const MAX_RUNS: usize = 512;
/// A run quiet this long is forgotten: its edge keeps nothing that old (10 s at most), so no
/// send of it can come again.
const RUN_FORGET: Duration = Duration::from_secs(60);

struct Run {
    /// Every id below it is settled.
    floor: u64,
    /// Ids at or above the floor handled in this term.
    ids: BTreeSet<u64>,
    last: Instant,
}

/// What a request is to the sequencer.
#[derive(Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Not handled in this term.
    New,
    /// Handled already, or below its edge's floor.
    Duplicate,
    /// Too many runs to remember one more.
    Full,
}

/// The ids handled in one term.
#[derive(Default)]
pub struct Handled {
    runs: HashMap<(String, u64), Run>,
}

impl Handled {
    /// Whether `submit` was handled already; notes its edge's floor (forgetting what is below it).
    pub fn check(&mut self, submit: &Submit, now: Instant) -> Verdict {
        let key = (submit.edge.clone(), submit.run);
        if !self.runs.contains_key(&key) && self.runs.len() >= MAX_RUNS {
            self.runs.retain(|_, r| now.saturating_duration_since(r.last) < RUN_FORGET);
            if self.runs.len() >= MAX_RUNS {
                return Verdict::Full;
            }
        }
        let run = self.runs.entry(key).or_insert(Run { floor: 0, ids: BTreeSet::new(), last: now });
        run.last = now;
        if submit.floor > run.floor {
            run.floor = submit.floor;
            run.ids = run.ids.split_off(&submit.floor);
        }
        if submit.n < run.floor || run.ids.contains(&submit.n) { Verdict::Duplicate } else { Verdict::New }
    }

    /// Notes `id` as handled (after [`Handled::check`] said it was new).
    pub fn mark(&mut self, id: &RequestId) {
        let Some(run) = self.runs.get_mut(&(id.edge.clone(), id.run)) else { return };
        if id.n < run.floor {
            return;
        }
        run.ids.insert(id.n);
        if run.ids.len() > MAX_IDS_PER_RUN
            && let Some(oldest) = run.ids.pop_first()
        {
            run.floor = oldest + 1;
            run.ids = run.ids.split_off(&run.floor);
        }
    }

    /// Forgets the runs quiet for [`RUN_FORGET`] (the sequencer calls it every second: without
    /// it a run was forgotten only once [`MAX_RUNS`] were kept).
    pub fn forget_quiet(&mut self, now: Instant) {
        self.runs.retain(|_, r| now.saturating_duration_since(r.last) < RUN_FORGET);
    }

    /// Runs remembered.
    #[cfg(test)]
    pub fn runs(&self) -> usize {
        self.runs.len()
    }

    /// Forgets `id`: a tick that carried it never reached the log, so its edge's next send of
    /// it must be taken.
    pub fn forget(&mut self, id: &RequestId) {
        if let Some(run) = self.runs.get_mut(&(id.edge.clone(), id.run)) {
            run.ids.remove(&id.n);
        }
    }

    /// Ids remembered, all runs together.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.runs.values().map(|r| r.ids.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::serve::bus::protocol::Wire;

    fn submit(n: u64, floor: u64) -> Submit {
        Submit { floor, ..Submit::new("a", 1, n, Wire::Clear) }
    }

    #[test]
    fn an_id_is_handled_once_until_forgotten() {
        let t0 = Instant::now();
        let mut h = Handled::default();
        let s = submit(5, 1);
        assert_eq!(h.check(&s, t0), Verdict::New);
        h.mark(&s.id());
        assert_eq!(h.check(&s, t0), Verdict::Duplicate);
        // Another run of the same edge counts anew.
        assert_eq!(h.check(&Submit { run: 2, ..s.clone() }, t0), Verdict::New);
        h.forget(&s.id());
        assert_eq!(h.check(&s, t0), Verdict::New);
    }

    #[test]
    fn the_edges_floor_and_the_bound_keep_it_small() {
        let t0 = Instant::now();
        let mut h = Handled::default();
        for n in 1..=100 {
            assert_eq!(h.check(&submit(n, 1), t0), Verdict::New);
            h.mark(&submit(n, 1).id());
        }
        assert_eq!(h.len(), 100);
        // The edge settled everything below 90: forgotten, and below the floor is handled.
        assert_eq!(h.check(&submit(101, 90), t0), Verdict::New);
        assert_eq!(h.len(), 11);
        assert_eq!(h.check(&submit(3, 90), t0), Verdict::Duplicate);
        // At most MAX_IDS_PER_RUN, the oldest going first.
        for n in 200..200 + 2 * MAX_IDS_PER_RUN as u64 {
            h.check(&submit(n, 90), t0);
            h.mark(&submit(n, 90).id());
        }
        assert_eq!(h.len(), MAX_IDS_PER_RUN);
        assert_eq!(h.check(&submit(200, 90), t0), Verdict::Duplicate);
    }
}
