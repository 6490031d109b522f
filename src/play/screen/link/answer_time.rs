//! The terminal's own time to answer, told apart from the link's queue.
//!
//! A round trip is the link's delay, the queue the frames built in it, and the time the
//! terminal takes to read the question and answer it. A terminal that draws in software on a
//! loaded machine takes its time: Debian's kitty 0.26 under llvmpipe answered 4970 questions
//! (recorded both ways between kitty and ssh) in a median of 18 ms, a 90th percentile of 98 ms,
//! and up to a second. Read as queue against a high mark of 30 ms, those answers lowered the
//! rate to the 2 kB/s floor within 5 s on a 250 kB/s link.
//!
//! **Measured, not modelled.** The only answer that shows the terminal's own time alone is one
//! to a question asked with nothing in flight: every byte before it already answered for. So
//! now and then ([`CLEAN_EVERY`]; the first ones sooner, [`CLEAN_FIRST_EVERY`]) the link holds
//! its frames until the question in flight is answered, asks a bare question, and sends frames
//! again at once (they follow the question, so they cannot delay its answer): a pause of about a
//! round trip, like BBR's probe of the round trip with nothing queued. That answer's delay
//! beyond the base round trip is the terminal's own. [`AnswerTime`] keeps the last [`SAMPLES`]
//! of them; its median ([`AnswerTime::usual`]) is taken off every answer's queue, and its slow
//! answers ([`AnswerTime::slow`]) widen the high mark.
//!
//! An earlier version (round 4) inferred the terminal's time from the bytes in flight, timed at
//! the link's capacity as seen. A terminal slow because it is still *reading* (a Python
//! terminal on a loaded machine, a sixel decoder in the reading thread) then looked like a fast
//! link with a slow terminal: its backlog was learned as "own time", up to 100 ms of queue went
//! unseen, and the link harness's key-to-effect p90 went from 16-104 ms to 169-374 ms. A
//! terminal still reading answers a bare question at once, so here its backlog stays a queue.

use std::time::Duration;

/// Answers remembered.
pub const SAMPLES: usize = 16;
/// The most the terminal's own time is allowed: beyond it the answers are too slow for keys
/// to show within a round trip anyway, and a queue must not hide behind them.
pub const OWN_MAX: Duration = Duration::from_millis(100);
/// How often the terminal's own time is measured once [`FIRST_SAMPLES`] are known, while it
/// is seen to matter (slow answers past the low mark): a terminal that draws slowly may draw
/// more slowly later. At least [`CLEAN_RTTS`] base round trips apart, so the pauses cost a few
/// per cent of the link.
pub const CLEAN_EVERY: Duration = Duration::from_secs(5);
/// How often while the terminal answers at once (its slow answers under the low mark).
pub const CLEAN_RARELY: Duration = Duration::from_secs(20);
/// How often it is measured until then: the first seconds decide whether the rate collapses.
pub const CLEAN_FIRST_EVERY: Duration = Duration::from_millis(300);
/// Measurements taken at the faster pace, and before which every terminal is taken for one slow
/// on its own: four were too few (kitty 0.26's answer times gave four bare answers of 0-8 ms
/// in one fake run of 18, and main's rules then took its stalls for queue: 12-45 kB/s).
pub const FIRST_SAMPLES: usize = CLEAN_SAMPLES;
/// The least gap between two measurements, in base round trips.
pub const CLEAN_RTTS: u32 = 40;
/// The longest the link holds its frames for a measurement beyond the base round trip; past it
/// the measurement is skipped until the next one is due (a terminal slow to answer the question
/// in flight must not freeze the picture).
pub const HOLD_MAX: Duration = Duration::from_millis(200);

/// When a measurement due at `due` is given up, on a base round trip of `base`.
pub fn hold_end(due: std::time::Instant, base: Duration) -> std::time::Instant {
    due + base + HOLD_MAX
}

/// The gap to the next measurement after one that came with `count` learned, the terminal's
/// slow answers `slow` against the low mark `low`, on a base round trip of `base`.
pub fn next_gap(count: usize, slow: Duration, low: Duration, base: Duration) -> Duration {
    let every = if count < FIRST_SAMPLES {
        CLEAN_FIRST_EVERY
    } else if slow > low {
        CLEAN_EVERY
    } else {
        CLEAN_RARELY
    };
    every.max(base * CLEAN_RTTS)
}
/// Bytes that may be in flight under a bare question (a status line's worth): the set-up and
/// cursor bytes a frame with no budget still writes.
pub const CLEAN_BYTES: u64 = 512;

/// Bare questions' answers remembered, to judge whether the terminal answers slowly at all.
pub const CLEAN_SAMPLES: usize = 8;

/// The terminal's own answer times: from answers to questions asked with nothing in flight,
/// and, once those show a terminal slow to answer at all, from answers the bytes in flight
/// cannot explain.
#[derive(Clone, Debug, Default)]
pub struct AnswerTime {
    samples: [Duration; SAMPLES],
    count: usize,
    clean: [Duration; CLEAN_SAMPLES],
    clean_count: usize,
}

impl AnswerTime {
    /// A bare question's answer came `excess` after the base round trip.
    pub fn record(&mut self, excess: Duration) {
        self.clean[self.clean_count % CLEAN_SAMPLES] = excess;
        self.clean_count += 1;
        self.push(excess);
    }

    /// An answer came `excess` after the base round trip behind bytes that would have queued
    /// `in_flight` at the capacity seen, with the queue's marks `low` and `high`. It teaches only when
    /// those bytes made no queue to speak of and the bare questions have shown the terminal
    /// slow to answer ([`AnswerTime::is_slow`]): a few bare answers cannot show a
    /// heavy tail (kitty 0.26: a median of 18 ms, a 90th percentile of 98 ms), and a terminal
    /// that answers bare questions at once is late only because it is still reading.
    pub fn infer(&mut self, excess: Duration, in_flight: Duration, (low, high): (Duration, Duration)) {
        if in_flight <= low && self.is_slow(low, high) {
            self.push(excess.saturating_sub(in_flight));
        }
    }

    /// Whether the last bare questions have shown the terminal slow to answer on its own,
    /// with the queue's marks `low` and `high`: two of their answers past the low mark, or one
    /// past the high mark (kitty 0.26: three answers in four past 10 ms, one in five past
    /// 60 ms; the harness's Python terminal: 0-11 ms). Only such a terminal's late answers are
    /// weighed against the bytes in flight; one that answers bare questions at once is late
    /// only because it is still reading, and is treated as a queue at once.
    pub fn is_slow(&self, low: Duration, high: Duration) -> bool {
        let n = self.clean_count.min(CLEAN_SAMPLES);
        let mut clean = self.clean;
        clean[..n].sort_unstable();
        n > 0 && (clean[n - 1] > high || (n > 1 && clean[n - 2] > low))
    }

    /// Whether the terminal is to be treated as slow on its own: shown so
    /// ([`AnswerTime::is_slow`]), or not judged yet (fewer than [`FIRST_SAMPLES`] bare answers).
    pub fn treat_as_slow(&self, (low, high): (Duration, Duration)) -> bool {
        self.clean_count < FIRST_SAMPLES || self.is_slow(low, high)
    }

    fn push(&mut self, excess: Duration) {
        self.samples[self.count % SAMPLES] = excess;
        self.count += 1;
    }

    /// How many bare questions' answers were learned from (all time).
    pub fn bare_count(&self) -> usize {
        self.clean_count
    }

    /// The last samples, sorted, and how many there are.
    fn sorted(&self) -> ([Duration; SAMPLES], usize) {
        let n = self.count.min(SAMPLES);
        let mut sorted = self.samples;
        sorted[..n].sort_unstable();
        (sorted, n)
    }

    /// The terminal's usual time to answer (the median), at most [`OWN_MAX`]; zero until
    /// one is known.
    pub fn usual(&self) -> Duration {
        let (sorted, n) = self.sorted();
        if n == 0 { Duration::ZERO } else { sorted[n / 2].min(OWN_MAX) }
    }

    /// The terminal's slow answers: the second slowest of the last [`SAMPLES`] (about the
    /// 90th percentile; one very slow answer in sixteen is passed over; the slowest while
    /// fewer than four are known), at most [`OWN_MAX`].
    pub fn slow(&self) -> Duration {
        let (sorted, n) = self.sorted();
        match n {
            0 => Duration::ZERO,
            1..=3 => sorted[n - 1].min(OWN_MAX),
            _ => sorted[n - 2].min(OWN_MAX),
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
    fn the_usual_and_slow_answers_come_from_the_samples_within_own_max() {
        let mut time = AnswerTime::default();
        assert_eq!((time.usual(), time.slow()), (ms(0), ms(0)), "nothing learned yet");
        time.record(ms(7));
        assert_eq!((time.usual(), time.slow()), (ms(7), ms(7)), "one sample is both");
        let mut time = AnswerTime::default();
        // The terminal's own times: 2..=15 ms, and two of 101 and 901 ms.
        for i in 0..14 {
            time.record(ms(2 + i));
        }
        time.record(ms(101));
        time.record(ms(901));
        assert_eq!(time.usual(), ms(10), "the median of 2..=15, 101 and 901 ms");
        assert_eq!(
            time.slow(),
            ms(100),
            "the second slowest, within OWN_MAX: one slow answer in sixteen is passed over"
        );
        // Old samples leave as new ones come.
        for _ in 0..SAMPLES {
            time.record(ms(1));
        }
        assert_eq!((time.usual(), time.slow(), time.bare_count()), (ms(1), ms(1), 2 * SAMPLES));
    }
}
