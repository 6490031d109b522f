//! Recording a session: events collected in memory, saved whole when the session ends.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{Entry, Header, event_line, header_line};
use crate::error::Result;
use crate::scene::Event;
use crate::storage::Storage;

/// Collects a session's events and saves them through a [`Storage`] when the session ends
/// (on `q`, on a signal, or when dropped during a panic), so a replay on disk is always whole.
pub struct Recorder {
    path: PathBuf,
    text: String,
    finished: bool,
    step: u64,
    storage: Arc<dyn Storage>,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder").field("path", &self.path).field("step", &self.step).finish_non_exhaustive()
    }
}

impl Recorder {
    /// A recorder that will save to `path` through `storage`.
    pub fn new(path: &Path, header: &Header, storage: Arc<dyn Storage>) -> Recorder {
        let mut text = header_line(header);
        text.push('\n');
        Recorder { path: path.to_owned(), text, finished: false, step: 0, storage }
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

    /// Adds the end line and saves the file (once; later calls do nothing).
    pub fn finish(&mut self, step: u64) -> Result<()> {
        if self.finished {
            return Ok(());
        }
        self.record(step, Event::End);
        self.finished = true;
        self.storage.save(&self.path, self.text.as_bytes())
    }
}

impl Drop for Recorder {
    /// A session cut short by a panic still leaves a complete replay of what happened.
    fn drop(&mut self) {
        let _ = self.finish(self.step);
    }
}
