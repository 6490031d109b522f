//! The controller's side that the Screen reads besides the loop of frames, questions and
//! answers: the status line's hint, the question to ask, the probe's answers, and the answers
//! to wait for at the end.

use super::{LinkControl, LinkPath, Question};
use std::time::{Duration, Instant};

/// What the Screen calls besides the loop above: the path, the status line's hint, the probe's
/// answers, the answers to wait for at the end.
impl LinkControl {
    /// A few words for the status line when the link cannot be measured and the rate is a
    /// guess ([`SAFE_RATE`](super::SAFE_RATE)): how to set it. At most 67 characters: on a 160-column status
    /// line they leave the rate and the stone size beside them.
    pub fn hint(&self) -> Option<&'static str> {
        match self.path {
            // The wrapped question is answered (or has not waited long yet).
            LinkPath::Multiplexer(_) if self.path.asks_status() && !self.silent => None,
            LinkPath::Multiplexer("tmux") => {
                Some("tmux: set -g allow-passthrough on, or --bandwidth (250k = 2 Mbit/s)")
            }
            LinkPath::Multiplexer("screen") => {
                Some("screen: terminal not answering, set --bandwidth (250k = 2 Mbit/s)")
            }
            LinkPath::Multiplexer(_) => {
                Some("multiplexer over SSH: link not measured, set --bandwidth (250k = 2 Mbit/s)")
            }
            LinkPath::Mosh => Some("mosh: link not measured, set --bandwidth (250k = 2 Mbit/s)"),
            LinkPath::Direct if self.silent => Some("the terminal does not answer: set --bandwidth (250k = 2 Mbit/s)"),
            LinkPath::Direct => None,
        }
    }

    /// The link's question, to follow a frame ([`LinkPath::question`]).
    pub fn question(&self) -> &'static [u8] {
        self.path.question()
    }

    /// Whether the link's answers are device status reports ([`LinkControl::status_answered`])
    /// rather than device attributes ([`LinkControl::answered`]).
    pub fn asks_status(&self) -> bool {
        self.path.asks_status()
    }

    /// The last round trip measured.
    #[cfg(test)]
    pub fn last_rtt(&self) -> Option<Duration> {
        self.last_rtt
    }

    /// Answers counted as foreign ([`LinkControl::expect_foreign`]) and answers that came with
    /// no question waiting, so far.
    #[cfg(test)]
    pub fn dropped_answers(&self) -> (u64, u64) {
        (self.foreign_answers, self.stray_answers)
    }

    /// Takes the terminal for one that answers at once (four bare answers with no delay), as
    /// a test that is about the link and not the terminal needs.
    #[cfg(test)]
    pub fn known_fast(&mut self) {
        for _ in 0..super::answer_time::FIRST_SAMPLES {
            self.answer_time.record(Duration::ZERO);
        }
    }

    /// How many answers are still expected (link and foreign questions): at the end, wait a
    /// little for them, or they reach the shell as typed text.
    pub fn awaiting(&self) -> usize {
        self.questions.len
    }

    /// `count` DA1 questions somebody else asked (the graphics probe) are still to be answered,
    /// ahead of every link question asked from now on: their answers are counted and dropped.
    /// Until they come, or [`FOREIGN_WAIT`](super::FOREIGN_WAIT) has passed, no link question is asked, so an answer
    /// that never comes cannot shift the pairing.
    pub fn expect_foreign(&mut self, now: Instant, count: usize) {
        // (Called by the Screen when the probe's questions go out.)
        for _ in 0..count {
            if !self.questions.push(Question {
                asked: now,
                out: now,
                bytes: 0,
                foreign: true,
                overdue: false,
                app_limited: false,
                clean: false,
                in_flight: Duration::ZERO,
            }) {
                break;
            }
        }
    }

    /// Whether a question of the link's own is waiting for its answer.
    pub fn asking(&self) -> bool {
        self.questions.iter().any(|q| !q.foreign)
    }

    /// Whether an answer to somebody else's question is still due here (the Screen then gives
    /// the next device-attributes answer to the probe and lets this queue drop its place).
    pub fn foreign_due(&self) -> bool {
        self.questions.iter().next().is_some_and(|q| q.foreign)
    }
}
