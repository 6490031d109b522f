//! The subcommands: validated flags in, files and terminal output out.

pub mod bench;
pub mod play;
pub mod render;
pub mod replay;

use crate::cli::{Cli, Command};
use crate::error::Result;

/// A summary of the commands (`tidepool` alone plays the pool).
pub const GETTING_STARTED: &str = "\
tidepool: water you can play with in any terminal.

  tidepool                              play with the pool full-screen (keys: ? in the player)
  tidepool render pool                  render the ripple pool to pool.png
  tidepool render pool --out - --size 120x60
                                        draw it in this terminal as half-block text
  tidepool render pool --help           every flag, with defaults and units
  tidepool --help                       all commands";

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    crate::signals::install();
    match cli.command {
        Some(Command::Render(render)) => render::run(render),
        Some(Command::Bench(args)) => bench::run(args),
        Some(Command::Play(play)) => play::run(play),
        None => match <Cli as clap::Parser>::try_parse_from(["tidepool", "play"]) {
            Ok(Cli { command: Some(Command::Play(play)) }) => play::run(play),
            _ => unreachable!("`tidepool play` with no flags always parses"),
        },
    }
}
