//! The bytes sent, as the link would carry them at the capacity seen: the queue they can
//! explain behind each question.
//!
//! A queue is a delay that grows with the bytes sent ahead of the question; the terminal's own
//! time does not. One late answer lowers the rate by itself only when these bytes explain it
//! (a terminal drawing in software answers late now and then with nothing queued). The
//! terminal's own time is not inferred from this model: a terminal still reading makes the
//! link look faster than it is, and its backlog would be taken for its own time (see
//! `answer_time`, which measures it instead).

use std::time::{Duration, Instant};

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
