//! The subcommands: validated flags in, files and terminal output out.

pub mod animate;
pub mod bench;
pub mod docs;
pub mod lake;
pub mod ocean;
pub mod play;
pub mod render;
pub mod replay;
pub mod spectrum;

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
  tidepool render ocean --beaufort 6    a wind-driven sea in ocean.png
  tidepool spectrum --wind 10           the sea state a 10 m/s wind raises
  tidepool render lake --wind 0         a calm lake mirroring its shore in lake.png
  tidepool --help                       all commands";

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    crate::signals::install();
    match cli.command {
        Some(Command::Render(render)) => render::run(render),
        Some(Command::Spectrum(args)) => spectrum::run(args),
        Some(Command::Bench(args)) => bench::run(args),
        Some(Command::Completions(args)) => docs::completions(args),
        Some(Command::Man(args)) => docs::man(args),
        Some(Command::Play(play)) => play::run(play),
        None => match <Cli as clap::Parser>::try_parse_from(["tidepool", "play"]) {
            Ok(Cli { command: Some(Command::Play(play)) }) => play::run(play),
            _ => unreachable!("`tidepool play` with no flags always parses"),
        },
    }
}
