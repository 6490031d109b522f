//! `tidepool play` (and `tidepool` alone): the scene full-screen in this terminal.
//!
//! Everything that can fail on bad input (the background image, the record file's folder) is
//! checked here, before the terminal is taken over, so errors print on a normal screen.

use std::io::IsTerminal;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::play::{Bandwidth, HostConfig, Recording, ScreenConfig};
use crate::play::{ColorMode, EncodeOptions};
use crate::term::door::PlayConfig;

use crate::cli::args::{ColorChoice, PlayCommand};
use crate::cli::error::{Error, Result};

/// `--color-threshold` when `SSH_CONNECTION` is set: invisible in a moving picture, and it
/// saves the bytes of colours that only flicker by a step or two.
pub const SSH_COLOR_THRESHOLD: u8 = 3;

/// `--color-threshold` when not given: 0 (exact) locally, [`SSH_COLOR_THRESHOLD`] over SSH.
pub fn default_threshold(ssh_connection: Option<&str>) -> u8 {
    if ssh_connection.is_some_and(|v| !v.trim().is_empty()) { SSH_COLOR_THRESHOLD } else { 0 }
}

/// Runs the player.
pub fn run(command: PlayCommand) -> Result<()> {
    if !std::io::stdout().is_terminal() {
        return Err(Error::Usage(
            "standard output is not a terminal, and the player draws full-screen in one; to write a picture to a file or a pipe use `tidepool render pool --out FILE|-`".into(),
        ));
    }
    let env = |name: &str| std::env::var(name).ok();
    let color = match command.color {
        ColorChoice::Auto => ColorMode::detect(env("COLORTERM").as_deref(), env("TERM").as_deref()),
        ColorChoice::Truecolor => ColorMode::TrueColor,
        ColorChoice::Palette256 => ColorMode::Palette256,
        ColorChoice::Palette16 => ColorMode::Palette16,
    };
    let threshold = command.color_threshold.unwrap_or(default_threshold(env("SSH_CONNECTION").as_deref()));
    if command.record.is_some() && command.scene != crate::cli::args::PlayScene::Pool {
        return Err(Error::arg(
            "--record",
            "replays hold the pool only; record with `tidepool play pool --record FILE`",
        ));
    }
    if let Some(path) = &command.record {
        crate::cli::files::check_writable(path).map_err(|message| Error::arg("--record", message))?;
    }
    let scenes = super::scenes::specs(command.scene, &command.water)?;
    let quit = Arc::new(AtomicBool::new(false));
    let host = HostConfig {
        scenes,
        seed: command.water.seed,
        record: command
            .record
            .clone()
            .map(|path| Recording { path, background: command.water.pool.background.clone() }),
        screenshots: true,
    };
    let screen = ScreenConfig {
        fps: command.fps,
        bandwidth: command.max_bps.map_or(command.bandwidth, Bandwidth::Fixed),
        color,
        color_auto: command.color == ColorChoice::Auto,
        // No hint where 24-bit colour draws worse (mlterm recycles its 24-bit colours).
        colour_hint: command.color == ColorChoice::Auto && ColorMode::truecolor_helps(env("TERM").as_deref()),
        encode: EncodeOptions { threshold, sync: !command.no_sync },
        graphics: command.graphics.into(),
        // The door asks the terminal itself when both ends are terminals, and finds what sits
        // between (a multiplexer over SSH, mosh).
        probe: None,
        link_path: crate::play::LinkPath::Direct,
    };
    let storage: Arc<dyn crate::storage::Storage> = Arc::new(crate::cli::files::AtomicStorage);
    let config = PlayConfig { host, screen, greeting: None, storage: Some(storage), quit: Arc::clone(&quit) };
    let _stop_on_signal = crate::cli::signals::StopOnSignal::new(quit);
    crate::term::tty::play(config).map_err(|e| match e {
        crate::Error::TooLarge { what, width, height } => {
            Error::Usage(format!("cannot allocate a {width}x{height} {what}; use a smaller terminal"))
        }
        other => Error::Lib(other),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threshold_is_exact_locally_and_3_over_ssh() {
        assert_eq!(default_threshold(None), 0);
        assert_eq!(default_threshold(Some("")), 0);
        assert_eq!(default_threshold(Some("10.0.0.1 52000 10.0.0.2 22")), 3);
    }
}
