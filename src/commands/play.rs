//! `tidepool play` (and `tidepool` alone): the scene full-screen in this terminal.
//!
//! Everything that can fail on bad input (the background image, the record file's folder) is
//! checked here, before the terminal is taken over, so errors print on a normal screen.

use std::io::IsTerminal;

use crate::cli::{ColorChoice, PlayCommand, PlayScene};
use crate::error::{Error, Result};
use crate::output::color::ColorMode;
use crate::output::diff::EncodeOptions;
use crate::render::ocean::OceanView;
use crate::render::texture::SeaTexture;
use crate::scene::lake::{LakeScene, LakeSettings};
use crate::scene::ocean::{OceanScene, OceanSettings};
use crate::scene::playable::Playable;
use crate::scene::pool::PoolScene;
use crate::sim::lake::LakeParams;
use crate::sim::ocean::SeaParams;
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

/// What to tell a user whose terminal was guessed to have fewer than 16 million colours.
///
/// SSH does not forward `COLORTERM` and tmux hides it, so most terminals that could show true
/// colour are guessed as 256-colour ones there, and the water loses its shades. Saying so in
/// the status line's first seconds tells the user the one flag that fixes it.
pub fn color_hint(choice: ColorChoice, mode: ColorMode) -> Option<String> {
    (choice == ColorChoice::Auto && mode != ColorMode::TrueColor)
        .then(|| format!("{} colours (no COLORTERM): try --color truecolor", mode.name()))
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
    let floor = command.pool.floor()?;
    if command.record.is_some() && command.scene != PlayScene::Pool {
        return Err(Error::arg(
            "--record",
            "replays hold the pool only; record with `tidepool play pool --record FILE`",
        ));
    }
    let rain = command.pool.rain.unwrap_or(DEFAULT_PLAYER_RAIN);
    let default_view = OceanView::default();
    let ocean = OceanSettings {
        sea: SeaParams {
            wind_m_s: command.wind.speed_m_s(),
            wind_from_deg: command.direction.unwrap_or(crate::cli::ocean::DEFAULT_DIRECTION_DEG),
            seed: command.seed,
            ..SeaParams::default()
        },
        view: OceanView {
            sun_azimuth_deg: command.pool.sun.map_or(default_view.sun_azimuth_deg, |s| s.azimuth_deg),
            sun_elevation_deg: command.pool.sun.map_or(default_view.sun_elevation_deg, |s| s.elevation_deg),
            ssaa: 1,
            ..default_view
        },
    };
    let texture = SeaTexture::builtin();
    let mut lake = lake_settings(command.seed);
    if command.wind.wind.is_some() || command.wind.beaufort.is_some() {
        lake.lake.wind_m_s = command.wind.speed_m_s().min(crate::scene::lake::MAX_LAKE_WIND_M_S);
    }
    let settings = command.pool.settings(command.seed, DEFAULT_PLAYER_RAIN);
    let too_big = |what: &str, width: u32, height: u32| {
        Error::Usage(format!("cannot allocate a {width}x{height} {what}; use a smaller terminal"))
    };
    let make: SceneFactory = Box::new(move |kind, width, height| match kind {
        PlayScene::Pool => PoolScene::new(width, height, floor.clone(), settings)
            .map(|scene| Box::new(scene) as Box<dyn Playable>)
            .ok_or_else(|| too_big("pool", width, height)),
        PlayScene::Ocean => OceanScene::new(ocean, width, height, texture.clone())
            .map(|scene| Box::new(scene) as Box<dyn Playable>)
            .ok_or_else(|| too_big("sea", width, height)),
        PlayScene::Lake => LakeScene::new(lake, width, height)
            .map(|scene| Box::new(scene) as Box<dyn Playable>)
            .ok_or_else(|| too_big("lake", width, height)),
    });
    let config = PlayerConfig {
        fps: command.fps,
        max_bps: command.max_bps,
        color,
        encode: EncodeOptions { threshold, sync: !command.no_sync },
        seed: command.seed,
        record: command.record.clone().map(|path| (path, super::replay::pool_options(&command.pool, rain))),
        greeting: color_hint(command.color, color),
    };
    app::run(command.scene, make, config)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_guessed_palette_says_how_to_get_true_colour() {
        assert!(color_hint(ColorChoice::Auto, ColorMode::Palette256).unwrap().contains("--color truecolor"));
        assert!(color_hint(ColorChoice::Auto, ColorMode::Palette16).unwrap().starts_with("16 colours"));
        assert_eq!(color_hint(ColorChoice::Auto, ColorMode::TrueColor), None);
        assert_eq!(color_hint(ColorChoice::Palette256, ColorMode::Palette256), None, "asked for: no hint");
    }

    #[test]
    fn threshold_is_exact_locally_and_3_over_ssh() {
        assert_eq!(default_threshold(None), 0);
        assert_eq!(default_threshold(Some("")), 0);
        assert_eq!(default_threshold(Some("10.0.0.1 52000 10.0.0.2 22")), 3);
    }
}
