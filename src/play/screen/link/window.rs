//! The window: how many bytes may be in flight, and the frames held while the terminal's own
//! time is measured (the bare question, `answer_time`).

use std::time::{Duration, Instant};

use super::{
    FIRST_TRICKLE, FIRST_WINDOW, FRAME_ALLOWANCE, LinkControl, MIN_WINDOW, WINDOW_QUEUE, WINDOW_RTT_MAX, answer_time,
};

impl LinkControl {
    /// How many more bytes may go out now, `bytes_sent` counting every byte written so far:
    /// the window less what is still unanswered for ([`usize::MAX`] for a terminal that does
    /// not answer).
    pub fn window_left(&self, now: Instant, bytes_sent: u64) -> usize {
        if self.is_silent(now) {
            return usize::MAX;
        }
        if self.holding(now) {
            // The terminal's own time is being measured: nothing more until the bytes in
            // flight are answered for and the bare question has gone out.
            return 0;
        }
        if self.waited_past_window(now) {
            // The window in time as in bytes: on a link faster than the frames need, the
            // bytes' window holds seconds of frames (5 MB/s for 0.35 s is 1.8 MB, 8 s of 7 kB
            // frames), and a terminal that stopped reading (paused, or its link stalled) got
            // them, to draw stale when it read again. Nothing more until the question is
            // answered or the terminal found silent.
            return 0;
        }
        let window = self.window(now);
        usize::try_from(window.saturating_sub(bytes_sent.saturating_sub(self.acknowledged))).unwrap_or(usize::MAX)
    }

    /// The window: the bytes that may be unanswered for at `now` (holds and bytes in flight
    /// aside); the first window until an answer has measured the link's capacity.
    pub(super) fn window(&self, now: Instant) -> u64 {
        if self.measured() {
            // The bandwidth-delay product: one question at a time, so two round trips (each
            // with the queue the window allows) and a frame; never below what the rate sends
            // in that time, and the link's capacity as seen, not a rate still growing past it.
            let taken = self.capacity.unwrap_or(self.rate).min(self.rate);
            (taken * self.window_time().as_secs_f64()).max(MIN_WINDOW as f64) as u64
        } else {
            let waited = self
                .questions
                .iter()
                .find(|q| !q.foreign)
                .map_or(Duration::ZERO, |q| now.saturating_duration_since(q.asked));
            FIRST_WINDOW + (FIRST_TRICKLE * waited.as_secs_f64()) as u64
        }
    }

    /// Whether an answer has measured the link's capacity (the window is then its
    /// bandwidth-delay product, and bounded in time too).
    fn measured(&self) -> bool {
        self.answered && self.capacity.is_some()
    }

    /// The time the window is sized for: one question at a time, so two round trips (each
    /// with the queue the window allows) and a frame.
    fn window_time(&self) -> Duration {
        let base = self.base().unwrap_or(Duration::ZERO).min(WINDOW_RTT_MAX);
        2 * (base + WINDOW_QUEUE) + FRAME_ALLOWANCE
    }

    /// Whether one of the link's questions has waited longer than the window's time, once the
    /// link is measured (before, the first window and the silence rule bound it); an overdue
    /// one too: its replacement would let another window's time of frames go each second.
    pub(super) fn waited_past_window(&self, now: Instant) -> bool {
        let time = self.window_time();
        self.measured() && self.questions.iter().any(|q| !q.foreign && now.saturating_duration_since(q.asked) > time)
    }

    /// Whether a question should follow even a frame that wrote nothing, `bytes_sent`
    /// counting every byte written so far: bytes went out after the last question (with none
    /// in flight, or a closed window would never open), or the terminal's own time is being
    /// measured and everything sent is answered for (the bare question, [`answer_time`]).
    pub fn question_wanted(&self, now: Instant, bytes_sent: u64) -> bool {
        bytes_sent > self.asked_up_to
            || (self.holding(now) && bytes_sent.saturating_sub(self.acknowledged) <= answer_time::CLEAN_BYTES)
    }

    /// Whether frames are held for a measurement of the terminal's own time: it is due, for
    /// at most [`answer_time::HOLD_MAX`] (a question in flight slow to be answered skips it).
    pub(super) fn holding(&self, now: Instant) -> bool {
        let base = self.base().unwrap_or(Duration::ZERO);
        self.clean_due.is_some_and(|due| now >= due && now < answer_time::hold_end(due, base))
            && !self.silent
            && self.path.answered_at_far_end()
    }
}
