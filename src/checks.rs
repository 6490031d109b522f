//! The checks of the plain numbers a person gives a scene's settings, as associated functions
//! of the settings they belong to. The binary's flag parsers read the text and call these; the
//! replay reader calls the same checks through the modules that own them. Each refusal names
//! the value and a good one; the caller adds where the value came from (a flag, a replay line).
//! (Values with a type of their own check themselves: [`crate::Stone::new`],
//! `Damping::from_str`, `Size`, [`crate::Refraction`], [`crate::Sun`].)

use crate::error::ValueError;
use crate::{LakeSettings, OceanSettings, PoolSettings};

impl PoolSettings {
    /// A light breeze: the player's level (`breeze` 0 is the papers' still water).
    pub const LIGHT_BREEZE: f64 = crate::sim::breeze::DEFAULT_LEVEL;

    /// Checks a rain rate, raindrops per step: finite and `0..=10000`.
    pub fn check_rain(rate: f64) -> Result<f64, ValueError> {
        crate::sim::rain::check_rate(rate)
    }

    /// Checks a breeze level, `0..=4`.
    pub fn check_breeze(level: f64) -> Result<f64, ValueError> {
        crate::sim::breeze::check_level(level)
    }

    /// Checks a grid, simulation cells per picture pixel along each axis, `1..=4`.
    pub fn check_grid(grid: u64) -> Result<u32, ValueError> {
        crate::scene::pool::check_grid(grid)
    }

    /// Checks a pace, simulation steps a second, `1..=240`.
    pub fn check_steps_per_second(steps: u64) -> Result<u32, ValueError> {
        crate::scene::pool::check_steps_per_second(steps)
    }
}

impl OceanSettings {
    /// Checks the sea's wind speed at 10 m, `0..=60` m/s.
    pub fn check_wind(m_s: f64) -> Result<f64, ValueError> {
        crate::sim::wind::check_sea_wind(m_s)
    }
}

impl LakeSettings {
    /// Checks the lake's wind speed at 10 m, `0..=30` m/s.
    pub fn check_wind(m_s: f64) -> Result<f64, ValueError> {
        crate::sim::wind::check_lake_wind(m_s)
    }

    /// Checks a count of noise octaves, `1..=12`.
    pub fn check_octaves(octaves: i64) -> Result<u32, ValueError> {
        crate::sim::lake::check_octaves(octaves)
    }

    /// Checks the noise's persistence (the amplitude ratio between octaves), `0..=1`.
    pub fn check_persistence(persistence: f64) -> Result<f64, ValueError> {
        crate::sim::lake::check_persistence(persistence)
    }
}
