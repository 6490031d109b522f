//! The subcommands: validated flags in, files and terminal output out.
//!
//! Each command is a leaf; they share the output plan ([`output`]), the stage timings
//! ([`stats`]), still pictures ([`still`]) and animations ([`animate`]), and never import each
//! other except through those.

pub mod animate;
pub mod bench;
pub mod docs;
pub mod inline;
pub mod lake;
pub mod maps;
pub mod ocean;
pub mod output;
pub mod play;
pub mod pool;
pub mod replay;
pub mod scenes;
pub mod spectrum;
pub mod stats;
pub mod still;

use crate::cli::args::{Cli, Command, RenderScene};
use crate::cli::error::Result;

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    // The server answers SIGTERM and Ctrl-C itself: it says goodbye to every player first.
    #[cfg(feature = "serve")]
    if let Some(Command::Serve(args)) = cli.command {
        return crate::cli::serve::run(args);
    }
    crate::cli::signals::install();
    match cli.command {
        Some(Command::Render(render)) => match render.scene {
            RenderScene::Pool(args) => match args.replay.clone() {
                Some(path) => replay::render(&args, &path),
                None => pool::render(args),
            },
            RenderScene::Ocean(args) => ocean::render(args),
            RenderScene::Lake(args) => lake::render(args),
        },
        Some(Command::Spectrum(args)) => spectrum::run(args),
        Some(Command::Bench(args)) => bench::run(args),
        Some(Command::Completions(args)) => docs::completions(args),
        Some(Command::Man(args)) => docs::man(args),
        Some(Command::Play(play)) => play::run(play),
        #[cfg(feature = "serve")]
        Some(Command::Serve(_)) => unreachable!("served above, before the signal handlers"),
        #[cfg(not(feature = "serve"))]
        Some(Command::Serve(_)) => Err(crate::cli::error::Error::Usage(
            "this tidepool was built without `serve` (the SSH server is a feature, to keep the first build short): \
             run `cargo run --release --features serve -- serve`, or install it with `cargo install --path . --features serve`"
                .into(),
        )),
        None => match <Cli as clap::Parser>::try_parse_from(["tidepool", "play"]) {
            Ok(Cli { command: Some(Command::Play(play)) }) => play::run(play),
            _ => unreachable!("`tidepool play` with no flags always parses"),
        },
    }
}
