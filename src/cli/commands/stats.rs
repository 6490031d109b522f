//! `--stats`: how long each stage of a render took, printed to standard error.

use std::time::{Duration, Instant};

/// Per-stage timings of one render.
#[derive(Debug, Default)]
pub struct Stats {
    stages: Vec<(&'static str, Duration, String)>,
}

impl Stats {
    /// Records that `stage` ran from `started` until now; `detail` says what it did.
    pub fn record(&mut self, stage: &'static str, started: Instant, detail: String) {
        self.stages.push((stage, started.elapsed(), detail));
    }

    /// Prints [`Stats::report`] to standard error when `--stats` asked for it.
    pub fn print_if(&self, asked: bool) {
        if asked {
            eprint!("{}", self.report());
        }
    }

    /// The stages as aligned lines: name, milliseconds, detail.
    pub fn report(&self) -> String {
        let mut text = String::new();
        for (stage, took, detail) in &self.stages {
            text.push_str(&format!("{stage:<10} {:>9.2} ms   {detail}\n", took.as_secs_f64() * 1e3));
        }
        let total: Duration = self.stages.iter().map(|(_, took, _)| *took).sum();
        text.push_str(&format!("{:<10} {:>9.2} ms\n", "total", total.as_secs_f64() * 1e3));
        text
    }
}
