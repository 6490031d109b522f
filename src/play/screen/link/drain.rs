//! The start's end: the first time the link shows its limit, the queue the start built is
//! drained before the rate settles near the link.
//!
//! The start overshoots by design ([`START_RATE`], growing by [`INCREASE`] a round trip, held
//! only by the window): it finds a fast link within a few frames. On a slow long link what it
//! leaves is a queue of seconds, and the first takes (the bytes between two answers over the
//! time between them) cannot size the rate or the window that drains it: on the stock
//! 256 kbit/s 300 ms lab they read 34 kB/s over ssh (the token bucket's burst crossed at once)
//! and 48-59 kB/s over serve (its first answers came 350 and 125 ms late) on a link that
//! carried 29 kB/s of the player's bytes, so the window let 1.9 s of queue stand three to five
//! seconds in, when the first keys are pressed. One fall of [`DRAIN_SHARE`] from a rate sized
//! by them still ran over the link.
//!
//! So the first fall is a drain (BBR's DRAIN): the rate goes to [`DRAIN_START_SHARE`] of the
//! least the terminal was seen to take since the start (each take reads high for its own
//! reason, seldom all of them), and holds there, neither falling nor growing, until an answer
//! to a question asked since shows the queue under the low mark (or [`DRAIN_RTTS`] base round
//! trips have passed).
//! It then starts from [`DRAIN_SHARE`] of what the terminal took while the drain's queue still
//! stood (the link's own rate: it was busy all through), or of that least take when no such
//! take came, and grows gently from there ([`INCREASE_AFTER_LIMIT`]).
//!
//! [`START_RATE`]: super::START_RATE
//! [`INCREASE`]: super::INCREASE
//! [`INCREASE_AFTER_LIMIT`]: super::INCREASE_AFTER_LIMIT

use std::time::{Duration, Instant};

use super::{Change, DRAIN_SHARE, LinkControl, MIN_RATE, QUEUE_HIGH};

/// The share of the least take the start's queue drains at: under the link even when that take
/// read half again as high as the link.
pub const DRAIN_START_SHARE: f64 = 0.5;
/// On a long link the start grows by [`INCREASE`] only while the terminal takes at least this
/// share of the rate.
pub const START_KEEP_UP: f64 = 0.8;
/// The longest a drain lasts, in base round trips (and at least [`DRAIN_MIN_TIME`]): a queue that
/// will not read under the low mark (a terminal slow on its own) ends it all the same.
pub const DRAIN_RTTS: u32 = 6;
/// The shortest limit of a drain.
pub const DRAIN_MIN_TIME: Duration = Duration::from_millis(500);

/// What the start and its drain have seen of the link.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Drain {
    /// Since when the start's queue is being drained.
    pub(super) since: Option<Instant>,
    /// The least the terminal was seen to take before the drain ended.
    least_take: Option<f64>,
    /// The most it took during the drain while a queue stood from the interval's start.
    link: Option<f64>,
    /// The drain is over (it happens once).
    done: bool,
}

impl Drain {
    /// A take, `busy` when a queue stood at both its ends (the link was busy all through: it is
    /// the link's own rate).
    pub(super) fn took(&mut self, take: f64, busy: bool) {
        if self.done {
            return;
        }
        if self.since.is_none() {
            self.least_take = Some(self.least_take.map_or(take, |t| t.min(take)));
        } else if busy {
            self.link = Some(self.link.map_or(take, |l| l.max(take)));
        }
    }

    /// Whether the start's queue is being drained (the rate neither falls nor grows).
    pub(super) fn draining(&self) -> bool {
        self.since.is_some() && !self.done
    }

    /// Whether a take has been seen (the drain's rate is sized from them).
    pub(super) fn has_take(&self) -> bool {
        self.least_take.is_some()
    }

    /// Whether the next fall is the first: a drain.
    pub(super) fn first_fall(&self) -> bool {
        !self.done && self.since.is_none()
    }
}

impl LinkControl {
    /// Whether the next fall is the start's drain: the first, on a link whose base round trip
    /// `base` is past the high mark's ceiling, with a take to size it from.
    pub(super) fn drain_due(&self, base: Duration) -> bool {
        base > QUEUE_HIGH && self.drain.first_fall() && self.drain.has_take()
    }

    /// The first fall: the rate drains the start's queue at [`DRAIN_START_SHARE`] of the least
    /// take seen (or falls by `fallback` of itself when none is known).
    pub(super) fn start_drain(&mut self, now: Instant, fallback: f64) -> Change {
        let target = self.drain.least_take.map_or(self.rate * fallback, |t| t * DRAIN_START_SHARE);
        self.rate = target.min(self.rate).max(MIN_RATE);
        self.drain.since = Some(now);
        self.decided_at = Some(now);
        self.fell_at = Some(now);
        self.fell = true;
        Change::Down
    }

    /// An answer to a question asked at `asked` while the start's queue drains, the link's queue
    /// `link_queue` against the low mark `low` on a base round trip `base`: `Some` while the
    /// drain decides (it holds, or it ends and the rate starts near the link).
    pub(super) fn drain_step(
        &mut self,
        asked: Instant,
        link_queue: Duration,
        (low, base): (Duration, Duration),
        now: Instant,
    ) -> Option<Change> {
        let since = self.drain.since.filter(|_| !self.drain.done)?;
        let limit = (base * DRAIN_RTTS).max(DRAIN_MIN_TIME);
        let drained = asked >= since && link_queue < low;
        if !drained && now < since + limit {
            return Some(Change::Hold);
        }
        self.drain.done = true;
        let link = self.drain.link.or(self.drain.least_take)?;
        let rate = (link * DRAIN_SHARE).max(self.rate).min(self.ceiling);
        // Growth past the link's rate is gentle (`decide`); with no take of the link's own, it
        // is gentle from here: the least take may still read high (by the burst of a token
        // bucket: 14 % on the stock lab), and 3 % a round trip up to it queued 270 ms.
        self.link_rate = Some(self.drain.link.unwrap_or(rate));
        let change = if rate > self.rate { Change::Up } else { Change::Hold };
        self.rate = rate;
        self.decided_at = Some(now);
        Some(change)
    }
}
