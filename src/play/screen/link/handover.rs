//! When the question left the player: the player's own lateness, told apart from the link's
//! queue.
//!
//! A frame is planned at `now` (its budget, the question's place after it) and then built: the
//! scene's steps, its picture, the encoding, kitty's files. On a machine short of CPU that
//! takes the player most of a frame interval and varies with the load, and a question timed
//! from `now` carried it into its round trip. Measured at load 6 (a debug player beside a fake
//! kitty 0.26, `scripts`-less: the integration test `a_kitty_slow_to_answer_keeps_its_rate_over_ssh`,
//! traced): frames took 40-146 ms to build (a median of 75 ms, 25-60 ms of it waiting for a
//! core), the round trips a median of 109 ms and a p90 of 182 ms; from when each question was
//! handed to the writer, 25 and 93 ms. The spread of the building time was read as a queue of
//! 65-90 ms over the high mark, and each such answer lowered the rate (to 10 kB/s in CI beside
//! the other tests). The door says when the frame's bytes were handed to its writer
//! ([`LinkControl::handed_over`]); the round trip counts from there, so what it measures is the
//! link, the terminal and the player's read of the answer (stamped on arrival by the reading
//! thread), never the player's own work before the question went out.

use std::time::Instant;

use super::LinkControl;

impl LinkControl {
    /// The bytes of the last frame (with the question that follows it, if one was asked) were
    /// handed to the writer at `at`: the question left then, not when the frame was planned.
    /// A door that writes at once need not call it (the question then counts from the frame's
    /// `now`); one called twice, or with no question since the last call, changes nothing.
    pub fn handed_over(&mut self, at: Instant) {
        if !std::mem::take(&mut self.unwritten) {
            return;
        }
        if let Some(q) = self.questions.newest_own_mut() {
            let late = at.saturating_duration_since(q.out);
            q.out += late;
            // The bytes ahead of it had that long to cross before it left.
            q.in_flight = q.in_flight.saturating_sub(late);
        }
    }
}
