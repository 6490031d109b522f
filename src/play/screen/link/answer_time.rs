//! The terminal's own time to answer, told apart from the link's queue.
//!
//! A round trip is the link's delay, the queue the frames built in it, and the time the
//! terminal takes to read the question and answer it. A terminal that draws in software on a
//! loaded machine takes its time: Debian's kitty 0.26 under llvmpipe answered 4970 questions
//! (recorded both ways between kitty and ssh) in a median of 18 ms, a 90th percentile of 98 ms,
//! and up to a second. Read as queue against a high mark of 30 ms, those answers lowered the
//! rate to the 2 kB/s floor within 5 s on a 250 kB/s link.
//!
//! What tells them apart is the bytes in flight: a queue is a delay that grows with the bytes
//! sent ahead of the question, the terminal's time is not. [`Flight`] follows the bytes as the
//! link would carry them at the capacity seen (each question's `in_flight`: the queue they
//! would have made); the answers whose bytes made no queue to speak of (under the low mark)
//! show the terminal's own time, their delay beyond the base round trip less that queue.
//! [`AnswerTime`] keeps the last [`SAMPLES`] of them, like BBR's filter of the round trip with
//! nothing queued: its median ([`AnswerTime::usual`]) is taken off every answer's queue, and an
//! answer over the high mark counts as queue only when the bytes in flight explain it, or when
//! it is later than the terminal's slow answers ([`AnswerTime::slow`]) too.

use std::time::{Duration, Instant};

/// Answers remembered.
pub const SAMPLES: usize = 16;
/// The most the terminal's own time is allowed: beyond it the answers are too slow for keys
/// to show within a round trip anyway, and a queue must not hide behind them.
pub const OWN_MAX: Duration = Duration::from_millis(100);

/// The terminal's own answer times, from answers with (almost) nothing in flight.
#[derive(Clone, Debug, Default)]
pub struct AnswerTime {
    samples: [Duration; SAMPLES],
    count: usize,
}

impl AnswerTime {
    /// An answer came `excess` after the base round trip, behind bytes that would have queued
    /// `in_flight` on the link; `low` is the queue's low mark. Only answers whose bytes queued
    /// less than that are the terminal's to learn from.
    pub fn record(&mut self, excess: Duration, in_flight: Duration, low: Duration) {
        if in_flight <= low {
            self.samples[self.count % SAMPLES] = excess.saturating_sub(in_flight);
            self.count += 1;
        }
    }

    /// The last samples, sorted (none until a few were learned).
    fn sorted(&self) -> ([Duration; SAMPLES], usize) {
        let n = self.count.min(SAMPLES);
        let mut sorted = self.samples;
        sorted[..n].sort_unstable();
        (sorted, if n < 4 { 0 } else { n })
    }

    /// The terminal's usual time to answer (the median), at most [`OWN_MAX`].
    pub fn usual(&self) -> Duration {
        let (sorted, n) = self.sorted();
        if n == 0 { Duration::ZERO } else { sorted[n / 2].min(OWN_MAX) }
    }

    /// The terminal's slow answers: the second slowest of the last [`SAMPLES`] (about the
    /// 90th percentile; one very slow answer in sixteen is passed over), at most [`OWN_MAX`].
    pub fn slow(&self) -> Duration {
        let (sorted, n) = self.sorted();
        if n == 0 { Duration::ZERO } else { sorted[n - 2].min(OWN_MAX) }
    }
}

/// The bytes sent, as a link of the capacity seen would carry them: when it would have carried
/// everything sent so far.
#[derive(Clone, Debug, Default)]
pub struct Flight {
    /// When the link would have carried everything sent up to the last question.
    drained: Option<Instant>,
    /// The last question: when, and the bytes sent up to it.
    last: Option<(Instant, u64)>,
}

impl Flight {
    /// A question went out at `now` after `bytes_sent` bytes in all, the last frame's
    /// `frame` of them just before it, the link seen to carry `capacity` bytes a second: the
    /// queue those bytes would have made. The bytes since the last question are taken as sent
    /// evenly since it (the frames between are not timed here), the last frame's at once.
    pub fn sent(&mut self, now: Instant, bytes_sent: u64, frame: u64, capacity: f64) -> Duration {
        let (then, before) = self.last.unwrap_or((now, 0));
        let time = |bytes: u64| Duration::from_secs_f64((bytes as f64 / capacity.max(1.0)).min(60.0));
        let carried = time(bytes_sent.saturating_sub(before));
        let drained = (self.drained.map_or(then, |d| d.max(then)) + carried).max(now + time(frame));
        self.drained = Some(drained);
        self.last = Some((now, bytes_sent));
        drained.saturating_duration_since(now)
    }

    /// The answer to the question after `bytes` bytes came at `now`: the link had carried
    /// them by then, whatever the model said (it follows the link from what it was seen to
    /// do, not from a guess that runs on).
    pub fn answered(&mut self, now: Instant, bytes: u64) {
        if self.last.is_some_and(|(_, last)| bytes >= last) {
            self.drained = self.drained.map(|d| d.min(now));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    #[test]
    fn the_terminal_s_time_is_learned_where_no_bytes_queue() {
        let low = ms(10);
        let mut time = AnswerTime::default();
        assert_eq!((time.usual(), time.slow()), (ms(0), ms(0)), "nothing learned yet");
        // A queue: answers behind bytes that queue longer than the low mark teach nothing.
        for _ in 0..SAMPLES {
            time.record(ms(400), ms(390), low);
        }
        assert_eq!((time.usual(), time.slow()), (ms(0), ms(0)));
        // The terminal's own times: 1..=14 ms beyond their bytes, and two of 100 and 900 ms.
        for i in 0..14 {
            time.record(ms(2 + i), ms(1), low);
        }
        time.record(ms(101), ms(1), low);
        time.record(ms(901), ms(1), low);
        assert_eq!(time.usual(), ms(9), "the median of 1..=14, 100 and 900 ms");
        assert_eq!(time.slow(), ms(100), "the second slowest: one slow answer in sixteen is passed over");
        time.record(ms(2_000), ms(0), low);
        time.record(ms(2_000), ms(0), low);
        assert_eq!(time.slow(), OWN_MAX, "never more than OWN_MAX");
    }

    #[test]
    fn bytes_in_flight_queue_only_past_what_the_link_carries() {
        let t0 = Instant::now();
        let mut flight = Flight::default();
        // 25 kB at 250 kB/s: 100 ms to cross.
        assert_eq!(flight.sent(t0, 25_000, 25_000, 250_000.0), ms(100));
        // 50 ms later 5 kB more: the first 25 kB have 50 ms to go, then 20 ms.
        assert_eq!(flight.sent(t0 + ms(50), 30_000, 1_000, 250_000.0), ms(70));
        // A second later the link has carried everything: only the last frame's 2.5 kB queue.
        assert_eq!(flight.sent(t0 + ms(1_050), 100_000, 2_500, 250_000.0), ms(10));
    }
}
