//! Which edge is the sequencer: a lease in the pool's key-value bucket. The holder rewrites
//! the key every [`REFRESH`] with a compare-and-set on the revision it last wrote; an edge
//! that sees the same revision for [`EXPIRY`] by its own clock takes the key over with a
//! compare-and-set on that revision (so of several standbys one wins). A holder whose
//! compare-and-set fails has lost the lease and stops sequencing at once; the log's
//! expected-last-sequence check fences out any tick it still had in flight.
//!
//! Only what an edge saw counts: a standby that could not read the key (the bus away, or its
//! own link cut) starts its count again when it reads it next ([`Lease::lost_sight`]), and a
//! holder never gives the lease up by its clock alone, only when the compare-and-set says
//! another edge wrote. After nats-server restarts, every edge has been blind alike: without
//! the first rule a standby would take the key the moment it could read it, though its
//! holder is back and renewing (docs/serve/bus.md, round 4).
//!
//! Sans-IO: what the key holds and `now` in, what to write out.

use std::time::{Duration, Instant};

/// How often the holder rewrites the lease.
pub const REFRESH: Duration = Duration::from_millis(250);
/// How long a lease unchanged is taken as dead (four missed refreshes).
pub const EXPIRY: Duration = Duration::from_millis(1000);
/// How often a standby looks at the lease.
pub const POLL: Duration = Duration::from_millis(200);

/// What to write to the lease key next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeaseStep {
    /// Nothing now.
    Wait,
    /// The key is empty: create it (fails if another edge did first).
    Create,
    /// Write our name if the key is still at this revision (a refresh, or a takeover).
    Update(u64),
}

/// One edge's view of the lease.
#[derive(Debug)]
pub struct Lease {
    me: String,
    /// The revision last seen and when it was first seen.
    seen: Option<(u64, Instant)>,
    /// Our revision while we hold it.
    held: Option<u64>,
    /// When we last wrote it.
    wrote: Option<Instant>,
}

impl Lease {
    /// The lease as edge `me` sees it, holding nothing.
    pub fn new(me: &str) -> Lease {
        Lease { me: me.to_owned(), seen: None, held: None, wrote: None }
    }

    /// Our revision, while we hold the lease.
    pub fn held(&self) -> Option<u64> {
        self.held
    }

    /// The key read back: its holder and revision (`None`: no key, or deleted).
    pub fn observe(&mut self, entry: Option<(&str, u64)>, now: Instant) -> LeaseStep {
        let Some((holder, revision)) = entry else {
            self.held = None;
            self.seen = None;
            return LeaseStep::Create;
        };
        if self.seen.is_none_or(|(r, _)| r != revision) {
            self.seen = Some((revision, now));
        }
        if self.held == Some(revision) && holder == self.me {
            let due = self.wrote.is_none_or(|w| now.saturating_duration_since(w) >= REFRESH);
            return if due { LeaseStep::Update(revision) } else { LeaseStep::Wait };
        }
        // Someone else's key (or ours from before a restart: taken over like any other).
        self.held = None;
        match self.seen {
            Some((r, since)) if now.saturating_duration_since(since) >= EXPIRY => LeaseStep::Update(r),
            _ => LeaseStep::Wait,
        }
    }

    /// A create or update succeeded at `revision`: we hold the lease.
    pub fn wrote(&mut self, revision: u64, now: Instant) {
        self.held = Some(revision);
        self.seen = Some((revision, now));
        self.wrote = Some(now);
    }

    /// A create or update failed (another edge wrote first): we do not hold it.
    pub fn refused(&mut self) {
        self.held = None;
    }

    /// The key could not be read (the bus away, or this edge cut off from it): how long it
    /// stood unchanged is unknown, so a standby counts [`EXPIRY`] again from its next read.
    pub fn lost_sight(&mut self) {
        self.seen = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_edge_creates_the_lease_and_refreshes_it() {
        let t0 = Instant::now();
        let mut a = Lease::new("a");
        assert_eq!(a.observe(None, t0), LeaseStep::Create);
        a.wrote(1, t0);
        assert_eq!(a.held(), Some(1));
        assert_eq!(a.observe(Some(("a", 1)), t0 + REFRESH / 2), LeaseStep::Wait);
        assert_eq!(a.observe(Some(("a", 1)), t0 + REFRESH), LeaseStep::Update(1));
    }

    #[test]
    fn a_standby_takes_over_a_lease_unchanged_for_the_expiry_and_not_before() {
        let t0 = Instant::now();
        let mut b = Lease::new("b");
        assert_eq!(b.observe(Some(("a", 5)), t0), LeaseStep::Wait);
        // The holder refreshes: the standby's count starts again.
        assert_eq!(b.observe(Some(("a", 6)), t0 + EXPIRY / 2), LeaseStep::Wait);
        assert_eq!(b.observe(Some(("a", 6)), t0 + EXPIRY), LeaseStep::Wait);
        assert_eq!(b.observe(Some(("a", 6)), t0 + EXPIRY / 2 + EXPIRY), LeaseStep::Update(6));
        b.wrote(7, t0 + 2 * EXPIRY);
        assert_eq!(b.held(), Some(7));
    }

    #[test]
    fn a_holder_that_sees_another_name_has_lost_it() {
        let t0 = Instant::now();
        let mut a = Lease::new("a");
        a.wrote(1, t0);
        assert_eq!(a.observe(Some(("b", 2)), t0 + REFRESH), LeaseStep::Wait);
        assert_eq!(a.held(), None);
    }

    #[test]
    fn a_standby_that_lost_sight_of_the_lease_waits_a_whole_expiry_after_it_sees_it_again() {
        // The holder wrote revision 6, then nats-server went away for 1.5 s: the standby saw
        // revision 6 long ago, but not while the bus was down.
        let t0 = Instant::now();
        let mut b = Lease::new("b");
        assert_eq!(b.observe(Some(("a", 6)), t0), LeaseStep::Wait);
        b.lost_sight();
        let back = t0 + EXPIRY + EXPIRY / 2;
        assert_eq!(b.observe(Some(("a", 6)), back), LeaseStep::Wait, "taken the moment the bus came back");
        assert_eq!(b.observe(Some(("a", 6)), back + EXPIRY / 2), LeaseStep::Wait);
        // The holder did not renew within a whole expiry of the standby's sight: it is gone.
        assert_eq!(b.observe(Some(("a", 6)), back + EXPIRY), LeaseStep::Update(6));
        // A holder that lost sight keeps its revision: only a compare-and-set takes it away.
        let mut a = Lease::new("a");
        a.wrote(6, t0);
        a.lost_sight();
        assert_eq!(a.held(), Some(6));
        assert_eq!(a.observe(Some(("a", 6)), back), LeaseStep::Update(6));
    }
}
