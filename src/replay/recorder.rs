//! Recording a session: events collected in memory, handed out whole when the session ends.

use std::path::{Path, PathBuf};

use super::{Entry, Header, event_line, header_line};
use crate::scene::Event;

/// Collects a session's events; [`Recorder::finish`] hands out the whole replay file (its path
/// and its text) once, and the door saves it (on `q`, on a signal, or when the session ends
/// by a panic: the door's guard finishes the recording), so a replay on disk is always whole.
/// It writes nothing itself.
pub struct Recorder {
    path: PathBuf,
    text: String,
    finished: bool,
    step: u64,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder").field("path", &self.path).field("step", &self.step).finish_non_exhaustive()
    }
}

impl Recorder {
    /// A recorder of a replay to be saved at `path`.
    pub fn new(path: &Path, header: &Header) -> Recorder {
        let mut text = header_line(header);
        text.push('\n');
        Recorder { path: path.to_owned(), text, finished: false, step: 0 }
    }

    /// Records `event` at `step`.
    pub fn record(&mut self, step: u64, event: Event) {
        self.advance(step);
        if !self.finished {
            self.text.push_str(&event_line(&Entry { step, event }));
            self.text.push('\n');
        }
    }

    /// Notes that the session has reached `step` (where an interrupted session ends).
    pub fn advance(&mut self, step: u64) {
        self.step = self.step.max(step);
    }

    /// Adds the end line (at `step`, or the last step reached if later) and hands out the
    /// file to save: its path and its text. Once: later calls return `None`.
    pub fn finish(&mut self, step: u64) -> Option<(PathBuf, String)> {
        if self.finished {
            return None;
        }
        self.record(step.max(self.step), Event::End);
        self.finished = true;
        Some((self.path.clone(), std::mem::take(&mut self.text)))
    }
}
