//! The questions in flight, in the order asked: a terminal answers in order, so answers are
//! paired with them oldest first.

use std::time::Instant;

use super::MAX_QUESTIONS;

/// A question in flight, in the order asked.
#[derive(Clone, Copy, Debug)]
pub(super) struct Question {
    /// When the frame it follows began (its budget was planned then; its age counts from it).
    pub(super) asked: Instant,
    /// When it left the player: handed to the writer once the frame was built
    /// ([`super::LinkControl::handed_over`]), else as `asked`. Its round trip counts from here:
    /// the time the player took to build the frame is not the link's.
    pub(super) out: Instant,
    /// The bytes sent up to it (0 for a foreign one).
    pub(super) bytes: u64,
    /// Asked by somebody else (the graphics probe): its answer is dropped.
    pub(super) foreign: bool,
    /// Unanswered for longer than the loss timeout: counted as congestion once, its bytes
    /// taken as delivered; it keeps its place for its late answer.
    pub(super) overdue: bool,
    /// Every frame since the question before it left most of its budget unspent: the player,
    /// not the link, set the pace, so its answer says little of the link (see
    /// [`super::LinkControl::frame_sent`]).
    pub(super) app_limited: bool,
    /// Asked with nothing in flight (every byte before it answered for): its answer's delay
    /// beyond the base round trip is the terminal's own time ([`super::answer_time`]).
    pub(super) clean: bool,
    /// The queue the bytes sent up to it would have made on the link, at the capacity seen
    /// ([`super::flight::Flight`]): the part of its round trip the bytes can explain.
    pub(super) in_flight: std::time::Duration,
}

/// The questions in flight, oldest first (a fixed array: steady-state frames allocate nothing).
#[derive(Clone, Debug)]
pub(super) struct Questions {
    pub(super) list: [Option<Question>; MAX_QUESTIONS],
    pub(super) len: usize,
}

impl Questions {
    pub(super) fn iter(&self) -> impl Iterator<Item = &Question> {
        self.list[..self.len].iter().flatten()
    }

    pub(super) fn push(&mut self, question: Question) -> bool {
        if self.len == MAX_QUESTIONS {
            return false;
        }
        self.list[self.len] = Some(question);
        self.len += 1;
        true
    }

    /// The newest of the link's own questions.
    pub(super) fn newest_own_mut(&mut self) -> Option<&mut Question> {
        self.list[..self.len].iter_mut().rev().flatten().find(|q| !q.foreign)
    }

    pub(super) fn pop_oldest(&mut self) -> Option<Question> {
        let oldest = self.list[..self.len].first().copied().flatten()?;
        self.list.copy_within(1..self.len, 0);
        self.len -= 1;
        self.list[self.len] = None;
        Some(oldest)
    }

    /// Takes the oldest of the link's own questions out, the foreign ones keeping their places
    /// (a device status answer is never the probe's).
    pub(super) fn pop_oldest_own(&mut self) -> Option<Question> {
        let i = self.list[..self.len].iter().position(|q| q.is_some_and(|q| !q.foreign))?;
        let own = self.list[i];
        self.list.copy_within(i + 1..self.len, i);
        self.len -= 1;
        self.list[self.len] = None;
        own
    }

    /// Drops the questions `forget` says to, keeping the others in order.
    pub(super) fn forget(&mut self, mut forget: impl FnMut(&Question) -> bool) {
        let mut kept = 0;
        for i in 0..self.len {
            if let Some(q) = self.list[i].filter(|q| !forget(q)) {
                self.list[kept] = Some(q);
                kept += 1;
            }
        }
        self.list[kept..].fill(None);
        self.len = kept;
    }
}
