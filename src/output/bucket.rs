//! A token bucket: the byte budget of the rate-controlled encoder (filled at the link's rate,
//! each frame takes what it sends), and with other settings any rate limit (a server's bytes
//! for all its players, one player's actions a second).
//!
//! What a frame does not spend carries over, so a rate smaller than one cell a frame (1 kB/s
//! is 33 bytes a frame at 30 fps, less than one truecolor cell with its synchronized-output
//! markers) still sends a cell every few frames. The bucket holds at most [`MAX_BURST`] of
//! the rate (and never less than [`MIN_CAPACITY`] bytes, enough for any single cell): after a
//! quiet spell, one frame may send a burst that the link drains in that time, and no more, so
//! that no backlog forms behind it. Time comes in as an argument, so tests run on made-up
//! clocks.

use std::time::{Duration, Instant};

/// The most link time one frame may fill after the bucket has been left to fill up.
pub const MAX_BURST: Duration = Duration::from_millis(100);
/// The smallest capacity, in bytes: room for the costliest cell (a jump, both truecolor codes
/// and a glyph, about 50 bytes), the screen clear and the synchronized-output markers.
pub const MIN_CAPACITY: f64 = 256.0;
/// The most debt a picture frame may leave (see [`ByteBucket::owe`]), in time at the rate.
pub const MAX_DEBT: Duration = Duration::from_secs(10);

/// A bucket of bytes (or any tokens) refilled at a fixed rate, or an unlimited one.
#[derive(Clone, Debug)]
pub struct ByteBucket {
    /// Bytes per second; `None` for no limit.
    rate: Option<f64>,
    level: f64,
    last: Option<Instant>,
    /// How much of the rate it holds at most.
    burst: Duration,
    /// How much of the rate it may owe at most.
    max_debt: Duration,
}

impl ByteBucket {
    /// A bucket filled at `bytes_per_second` (at least 1), starting empty, holding at most
    /// `MAX_BURST` of the rate: a frame's budget.
    pub fn new(bytes_per_second: f64) -> ByteBucket {
        ByteBucket {
            rate: Some(bytes_per_second.max(1.0)),
            level: 0.0,
            last: None,
            burst: MAX_BURST,
            max_debt: MAX_DEBT,
        }
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// A rate limit: filled at `per_second`, starting full, holding and owing at most `burst`
    /// of the rate (a second for a server's limits: a short burst passes, a flood gets the rate).
    pub fn limit(per_second: f64, burst: Duration) -> ByteBucket {
        let rate = per_second.max(1e-9);
        ByteBucket { rate: Some(rate), level: rate * burst.as_secs_f64(), last: None, burst, max_debt: burst }
    }

    /// A bucket that never runs dry: [`ByteBucket::budget`] is
    /// [`crate::output::rate::UNLIMITED`].
    pub fn unlimited() -> ByteBucket {
        ByteBucket { rate: None, level: 0.0, last: None, burst: MAX_BURST, max_debt: MAX_DEBT }
    }

    /// The rate in bytes per second (`None`: unlimited).
    pub fn rate(&self) -> Option<f64> {
        self.rate
    }

    /// Changes the rate from now on (what is in the bucket stays, up to the new capacity).
    pub fn set_rate(&mut self, bytes_per_second: Option<f64>) {
        self.rate = bytes_per_second.map(|r| r.max(1.0));
        self.level = self.level.min(self.capacity());
    }

    /// The most the bucket holds, in bytes.
    pub fn capacity(&self) -> f64 {
        match self.rate {
            Some(rate) if self.burst == MAX_BURST => (rate * MAX_BURST.as_secs_f64()).max(MIN_CAPACITY),
            Some(rate) => rate * self.burst.as_secs_f64(),
            None => f64::INFINITY,
        }
    }

    /// Adds the bytes the rate allows since the last refill (nothing at the first call, which
    /// starts the clock).
    pub fn refill(&mut self, now: Instant) {
        if let (Some(rate), Some(last)) = (self.rate, self.last) {
            let elapsed = now.saturating_duration_since(last).as_secs_f64();
            self.level = (self.level + rate * elapsed).min(self.capacity());
        }
        if self.last.is_none_or(|last| now > last) {
            self.last = Some(now);
        }
    }

    /// The bytes the next frame may send.
    pub fn budget(&self) -> usize {
        match self.rate {
            // A hair over, so that 99.99999 bytes of float arithmetic is the 100 it stands for.
            Some(_) => (self.level + 1e-6) as usize,
            None => crate::output::rate::UNLIMITED,
        }
    }

    /// Takes the bytes a frame sent.
    pub fn spend(&mut self, bytes: usize) {
        if self.rate.is_some() {
            self.level = (self.level - bytes as f64).max(0.0);
        }
    }

    /// Takes the bytes of a frame bigger than the budget (a picture in real pixels, which
    /// cannot be cut to fit): the bucket goes into debt, and its budget stays 0 until the rate
    /// has repaid it. So such frames come as often as the rate allows, and never queue.
    pub fn owe(&mut self, bytes: usize) {
        if let Some(rate) = self.rate {
            // At most ten seconds of debt (a frame budget's bucket): a huge picture on a slow link
            // still shows now and then.
            self.level = (self.level - bytes as f64).max(-rate * self.max_debt.as_secs_f64());
        }
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// Takes `n` tokens at `now` if the bucket holds them (a rate limit: an action, a frame's
    /// bytes from a shared budget); says whether it did.
    pub fn try_take(&mut self, n: f64, now: Instant) -> bool {
        self.refill(now);
        match self.rate {
            None => true,
            Some(_) if self.level >= n => {
                self.level -= n;
                true
            }
            Some(_) => false,
        }
    }

    #[cfg(any(feature = "testing", test))]
    /// Whether the bucket is in debt (see [`ByteBucket::owe`]).
    pub fn in_debt(&self) -> bool {
        self.rate.is_some() && self.level < 0.0
    }

    /// Empties the bucket (for example when the link is found congested); a debt stays.
    pub fn drain(&mut self) {
        self.level = self.level.min(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 30);

    #[test]
    fn a_small_rate_adds_up_over_frames() {
        let start = Instant::now();
        let mut bucket = ByteBucket::new(1000.0);
        bucket.refill(start);
        assert_eq!(bucket.budget(), 0, "starts empty");
        let mut budgets = Vec::new();
        for frame in 1..=4 {
            bucket.refill(start + FRAME * frame);
            budgets.push(bucket.budget());
        }
        assert_eq!(budgets, [33, 66, 100, 133], "1 kB/s is 33 bytes a frame, carried over");
        bucket.spend(120);
        assert_eq!(bucket.budget(), 13);
    }

    #[test]
    fn the_bucket_holds_at_most_a_burst() {
        let start = Instant::now();
        let mut bucket = ByteBucket::new(100_000.0);
        bucket.refill(start);
        bucket.refill(start + Duration::from_secs(10));
        assert_eq!(bucket.budget(), 10_000, "100 ms of 100 kB/s");
        let mut slow = ByteBucket::new(10.0);
        slow.refill(start);
        slow.refill(start + Duration::from_secs(100));
        assert_eq!(slow.budget(), MIN_CAPACITY as usize, "room for a cell even on a very slow link");
        slow.set_rate(Some(1.0));
        assert_eq!(slow.budget(), MIN_CAPACITY as usize);
    }

    #[test]
    fn a_clock_going_backwards_adds_nothing() {
        let start = Instant::now() + Duration::from_secs(5);
        let mut bucket = ByteBucket::new(1000.0);
        bucket.refill(start);
        bucket.refill(start - Duration::from_secs(1));
        bucket.refill(start + Duration::from_millis(100));
        assert_eq!(bucket.budget(), 100);
    }

    #[test]
    fn a_picture_bigger_than_the_budget_is_owed_and_repaid_before_the_next() {
        let t0 = Instant::now();
        let mut b = ByteBucket::new(10_000.0);
        b.refill(t0);
        b.owe(5_000);
        assert!(b.in_debt());
        b.refill(t0 + Duration::from_millis(400));
        assert_eq!(b.budget(), 0, "4 000 of 5 000 bytes repaid: still nothing to spend");
        b.refill(t0 + Duration::from_millis(600));
        assert!(!b.in_debt());
        assert_eq!(b.budget(), 1_000);
        b.owe(10_000_000);
        b.refill(t0 + Duration::from_millis(600) + MAX_DEBT);
        assert!(!b.in_debt(), "the debt is capped at {MAX_DEBT:?} of the rate");
        let mut free = ByteBucket::unlimited();
        free.owe(1 << 30);
        assert!(!free.in_debt());
    }

    #[test]
    fn a_limit_starts_full_lets_a_burst_pass_and_then_the_rate() {
        let t0 = Instant::now();
        let mut actions = ByteBucket::limit(30.0, Duration::from_secs(1));
        let taken = (0..100).filter(|_| actions.try_take(1.0, t0)).count();
        assert_eq!(taken, 30, "a second's worth at once");
        assert!(!actions.try_take(1.0, t0 + Duration::from_millis(20)));
        assert!(actions.try_take(1.0, t0 + Duration::from_millis(40)), "one more after 1/30 s");
        let mut bytes = ByteBucket::limit(1000.0, Duration::from_secs(1));
        bytes.refill(t0);
        bytes.owe(5000);
        assert!(!bytes.try_take(0.0, t0 + Duration::from_millis(900)), "still owing");
        assert!(bytes.try_take(0.0, t0 + Duration::from_millis(1100)), "a second of debt at most: repaid after 1 s");
    }

    #[test]
    fn unlimited_is_unlimited() {
        let mut bucket = ByteBucket::unlimited();
        bucket.refill(Instant::now());
        bucket.spend(1 << 30);
        assert_eq!(bucket.budget(), crate::output::rate::UNLIMITED);
    }
}
