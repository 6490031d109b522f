//! Flags of the ripple pool, shared by `render pool` and the live scenes (`play`, `serve`),
//! and the defaults where they differ.

use crate::{BreezeStyle, CausticsLook, Damping, PoolSettings, Refraction, Sun};
use clap::Args;

use super::*;

/// The pool flags' defaults where `render` and the live scenes (`play`, `serve`) differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoolDefaults {
    /// `--rain`.
    pub rain: f64,
    /// `--breeze`.
    pub breeze: f64,
    /// `--breeze-style`.
    pub breeze_style: BreezeStyle,
    /// `--grid`.
    pub grid: u32,
    /// `--steps-per-second`.
    pub steps_per_second: u32,
}

impl PoolDefaults {
    /// `render pool`: the papers' still water, one cell a pixel, 60 steps a second.
    pub const RENDER: PoolDefaults =
        PoolDefaults { rain: 0.0, breeze: 0.0, breeze_style: BreezeStyle::Wavelets, grid: 1, steps_per_second: 60 };
    /// `play` and `serve`: water alive at rest that moves like water filmed at 30 fps and
    /// survives a slow link: gusts (broad swells of light drifting downwind), a few raindrops,
    /// a grid of two cells a pixel and 30 steps a second, so waves move a third of a pixel a
    /// frame instead of 1.4 pixels (`tests/integration/coherence.rs`, `benches/codec.rs`).
    pub const PLAYER: PoolDefaults = PoolDefaults {
        rain: 0.01,
        breeze: PoolSettings::LIGHT_BREEZE,
        breeze_style: BreezeStyle::Gusts,
        grid: 2,
        steps_per_second: 30,
    };
}

/// Flags of the ripple pool, shared by `render pool` and the player.
#[derive(Args, Debug, Clone)]
pub struct PoolArgs {
    /// Raindrops per simulation step on average (radius 2, weight 64), a number >= 0.
    /// [default: 0 for render, 0.01 for play]
    #[arg(long, value_name = "RATE", value_parser = parse_rate, allow_negative_numbers = true)]
    pub rain: Option<f64>,

    /// A light breeze over the water, so it is never still (0..=4; its style is --breeze-style;
    /// 0 is the papers' still water). [default: 0 for render, 1 for play]
    #[arg(long, value_name = "LEVEL", value_parser = parse_breeze, allow_negative_numbers = true)]
    pub breeze: Option<f64>,

    /// How the breeze moves the water: `gusts` (patches of ripples that rise and fade over
    /// seconds as they drift downwind: water as a camera films it at 30 fps) or `wavelets`
    /// (short wavelets that appear at once; the first breeze). [default: wavelets for render,
    /// gusts for play]
    #[arg(long, value_name = "STYLE", value_parser = parse_breeze_style)]
    pub breeze_style: Option<BreezeStyle>,

    /// Simulation cells per picture pixel along each axis (1..=4): a finer grid moves the
    /// waves 1/N pixels a step (they cross the picture N times slower, as if filmed from
    /// further away) and draws each pixel as the mean of its cells; 1 is the papers' pool, one
    /// cell a pixel. [default: 1 for render, 2 for play]
    #[arg(long, value_name = "N", value_parser = parse_grid)]
    pub grid: Option<u32>,

    /// Simulation steps per second of real time (1..=240): the pool's pace in the player and
    /// in animations (waves move 0.7/N pixels a step on a grid of N). [default: 60 for render,
    /// 30 for play]
    #[arg(long, value_name = "STEPS", value_parser = parse_steps_per_second)]
    pub steps_per_second: Option<u32>,

    /// Damping: each step the water loses 1/2^SHIFT of its amplitude (SHIFT 1..=15; higher
    /// calms more slowly), or `off` for none.
    #[arg(long, value_name = "SHIFT|off", default_value = "5", value_parser = parse_damping, allow_negative_numbers = true)]
    pub damping: Damping,

    /// How far the surface slope displaces the floor: 1.0 is the papers' factor, 0 shows the
    /// floor undistorted, `auto` scales with the picture (its smaller side / 720, between 0.15
    /// and 1) so ripples read as ripples at every size.
    #[arg(long, value_name = "F|auto", default_value = "auto", value_parser = parse_refraction, allow_negative_numbers = true)]
    pub refraction: Refraction,

    /// Do not light the surface (by default flanks facing the sun are brightened, the others
    /// darkened, and crests tilted towards the sun glint).
    #[arg(long)]
    pub no_shading: bool,

    /// Do not draw caustics (the moving lines of focused sunlight on the floor).
    #[arg(long)]
    pub no_caustics: bool,

    /// Water depth in pixels: deeper water focuses the caustics into sharper, brighter lines
    /// and moves them further from the ripples that cast them (0..=10000).
    #[arg(long, value_name = "PIXELS", default_value = "24", value_parser = parse_depth)]
    pub depth: CausticsLook,

    /// Where the sun is: azimuth in degrees clockwise from north (the top of the picture) and
    /// elevation in degrees above the horizon (0..=90). [default: 315,60 for the pool, the upper
    /// left; 15,22 for the ocean, ahead and low]
    #[arg(long, value_name = "AZ_DEG,EL_DEG", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: Option<Sun>,

    /// The pool floor: a PNG or JPEG, scaled to cover the picture (aspect kept, centred).
    /// [default: the built-in tiled floor]
    #[arg(long, value_name = "FILE")]
    pub background: Option<PathBuf>,
}

impl PoolArgs {
    /// The look these flags ask for.
    pub fn look(&self) -> crate::PoolLook {
        crate::PoolLook {
            refraction: self.refraction,
            shading: !self.no_shading,
            caustics: (!self.no_caustics).then_some(self.depth),
            sun: self.sun(),
        }
    }

    /// The pool's settings from these flags, with `seed`, and `defaults` for the flags not
    /// given (rain, breeze, its style and the grid); the floor is `--background` decoded, or
    /// the built-in tiles.
    pub fn settings(&self, seed: u64, defaults: PoolDefaults) -> crate::cli::error::Result<crate::PoolSettings> {
        Ok(crate::PoolSettings {
            damping: self.damping,
            rain_rate: self.rain.unwrap_or(defaults.rain),
            breeze: self.breeze.unwrap_or(defaults.breeze),
            breeze_style: self.breeze_style.unwrap_or(defaults.breeze_style),
            grid: self.grid.unwrap_or(defaults.grid),
            steps_per_second: self.steps_per_second.unwrap_or(defaults.steps_per_second),
            seed,
            look: self.look(),
            floor: self.floor()?,
        })
    }

    /// The pool floor: `--background` decoded, or the built-in tiles.
    pub fn floor(&self) -> crate::cli::error::Result<tiny_skia::Pixmap> {
        match &self.background {
            Some(path) => crate::render::background::load(path).map_err(crate::cli::error::Error::flag("--background")),
            None => Ok(crate::PoolSettings::default_floor()),
        }
    }

    /// The pool's sun: `--sun`, or the default in the upper left.
    pub fn sun(&self) -> Sun {
        self.sun.unwrap_or_default()
    }
}
