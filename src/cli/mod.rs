//! The `tidepool` command line (feature `cli`): its flags, its commands and the process wiring
//! (signals, progress bars, exit statuses) around the library, and `tidepool serve`'s SSH door
//! (`serve/`, feature `serve`). The binary, `src/bin/tidepool/main.rs`, only calls [`main`](crate::cli::main):
//! the command line lives in the library so that what it alone uses stays crate-private, and
//! the library's public API is what a library user needs, not everything the binary touches.
//!
//! [`main`](crate::cli::main) parses, runs and turns the result into an exit status: 0 on success (a closed pipe
//! on standard output counts as success: the reader has seen enough), 2 with one line on
//! standard error for any error, 128 + the signal number when a signal ended the run.

mod args;
mod commands;
mod error;
mod files;
mod progress;
#[cfg(feature = "serve")]
mod serve;
mod signals;

use std::process::ExitCode;

use clap::Parser;

/// Runs the `tidepool` command line on this process's arguments and returns its exit status.
pub fn main() -> ExitCode {
    let cli = args::Cli::parse();
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
