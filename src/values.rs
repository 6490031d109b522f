//! Checked readers for the numbers people type, with messages that say what is wrong and how
//! to fix it. Types that check themselves ([`crate::Stone`], [`crate::Damping`],
//! [`crate::Size`], [`crate::Refraction`], [`crate::Sun`], [`crate::NoiseKind`]) implement
//! `FromStr` instead; these are the plain numbers.

pub use crate::numbers::finite as parse_number;
pub use crate::scene::pool::{parse_grid, parse_steps_per_second};
pub use crate::sim::breeze::{DEFAULT_LEVEL as DEFAULT_BREEZE, parse_level as parse_breeze};
pub use crate::sim::lake::{parse_octaves, parse_persistence};
pub use crate::sim::rain::parse_rate as parse_rain_rate;
pub use crate::sim::wind::{parse_lake_wind, parse_sea_wind};
