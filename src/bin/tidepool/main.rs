//! The `tidepool` binary: the command line, its commands and the process wiring (signals,
//! progress bars, exit statuses) around the `tidepool` library.
//!
//! `main` parses, runs and turns the result into an exit status: 0 on success (a closed pipe on
//! standard output counts as success: the reader has seen enough), 2 with one line on standard
//! error for any error, 128 + the signal number when a signal ended the run.

mod cli;
mod commands;
mod error;
mod files;
mod progress;
#[cfg(feature = "serve")]
mod serve;
mod signals;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    let result = commands::run(cli);
    signals::wait_if_ending();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is_broken_pipe() => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tidepool: {e}");
            ExitCode::from(2)
        }
    }
}
