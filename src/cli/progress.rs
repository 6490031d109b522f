//! Progress on standard error for long headless work (many steps, many frames).
//!
//! Quiet unless standard error is a terminal, and silent for the first second, so quick
//! renders and pipelines print nothing; a long render shows a bar with a time estimate.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long work runs before a bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A progress bar that appears only when the work is slow and someone is watching.
pub struct Progress {
    bar: Option<ProgressBar>,
    label: &'static str,
    total: u64,
    done: u64,
    started: Instant,
    enabled: bool,
}

impl Progress {
    /// Progress over `total` units of `label` (e.g. "steps", "frames").
    pub fn new(label: &'static str, total: u64) -> Progress {
        Progress { bar: None, label, total, done: 0, started: Instant::now(), enabled: std::io::stderr().is_terminal() }
    }

    /// `units` more are done.
    pub fn advance(&mut self, units: u64) {
        self.done += units;
        if let Some(bar) = &self.bar {
            bar.set_position(self.done);
        } else if self.enabled && self.started.elapsed() >= SHOW_AFTER && self.done < self.total {
            let bar = ProgressBar::with_draw_target(Some(self.total), ProgressDrawTarget::stderr());
            let template = format!("{{bar:40.cyan/blue}} {{pos}}/{{len}} {} ({{per_sec}}, {{eta}} left)", self.label);
            if let Ok(style) = ProgressStyle::with_template(&template) {
                bar.set_style(style.progress_chars("█▓░"));
            }
            bar.set_position(self.done);
            self.bar = Some(bar);
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}
