//! `tidepool play` (and `tidepool` alone): the scene full-screen in this terminal.
//!
//! Everything that can fail on bad input (the background image, the record file's folder) is
//! checked here, before the terminal is taken over, so errors print on a normal screen.

use std::io::IsTerminal;

use crate::cli::{ColorChoice, PlayCommand, PlayScene};
use crate::error::{Error, Result};
use crate::output::color::ColorMode;
use crate::output::diff::EncodeOptions;
use crate::render::background;
use crate::scene::lake::{LakeScene, LakeSettings};
use crate::scene::playable::Playable;
use crate::scene::pool::{PoolScene, PoolSettings};
use crate::sim::lake::LakeParams;
use crate::term::app::{self, PlayerConfig, SceneFactory};

/// The player's rain when `--rain` is not given: about one drop a second at 60 steps/s.
pub const DEFAULT_PLAYER_RAIN: f64 = 0.02;
/// `--color-threshold` when `SSH_CONNECTION` is set: invisible in a moving picture, and it
/// saves the bytes of colours that only flicker by a step or two.
pub const SSH_COLOR_THRESHOLD: u8 = 3;

/// `--color-threshold` when not given: 0 (exact) locally, [`SSH_COLOR_THRESHOLD`] over SSH.
pub fn default_threshold(ssh_connection: Option<&str>) -> u8 {
    if ssh_connection.is_some_and(|v| !v.trim().is_empty()) { SSH_COLOR_THRESHOLD } else { 0 }
}

/// The lake the player starts with: the default breeze and noise, no supersampling (a
/// terminal cell is two pixels; the frame budget goes to the water instead).
pub fn lake_settings(seed: u64) -> LakeSettings {
    LakeSettings { lake: LakeParams { seed, ..LakeParams::default() }, ssaa: 1 }
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
    if command.record.is_some() && command.scene != PlayScene::Pool {
        return Err(Error::arg(
            "--record",
            "replays hold pool sessions only so far; play the pool (`tidepool play pool --record FILE`) or drop --record",
        ));
    }
    let floor = match &command.pool.background {
        Some(path) => background::load("--background", path)?,
        None => background::pool_floor(),
    };
    let rain = command.pool.rain.unwrap_or(DEFAULT_PLAYER_RAIN);
    let settings =
        PoolSettings { damping: command.pool.damping, rain_rate: rain, seed: command.seed, look: command.pool.look() };
    let make: SceneFactory = Box::new(move |kind, width, height| match kind {
        PlayScene::Pool => PoolScene::new(width, height, floor.clone(), settings)
            .map(|scene| Box::new(scene) as Box<dyn Playable>)
            .ok_or_else(|| Error::Usage(format!("cannot allocate a {width}x{height} pool; use a smaller terminal"))),
        PlayScene::Lake => LakeScene::new(lake_settings(command.seed), width, height)
            .map(|scene| Box::new(scene) as Box<dyn Playable>)
            .ok_or_else(|| Error::Usage(format!("cannot allocate a {width}x{height} lake; use a smaller terminal"))),
    });
    let config = PlayerConfig {
        fps: command.fps,
        max_bps: command.max_bps,
        color,
        encode: EncodeOptions { threshold, sync: !command.no_sync },
        seed: command.seed,
        record: command.record.clone().map(|path| (path, super::replay::pool_options(&command.pool, rain))),
    };
    app::run(command.scene, make, config)
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
