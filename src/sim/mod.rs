//! Simulations: state that advances in time. Nothing here draws or does I/O.

pub mod breeze;
pub mod dispersion;
pub mod fbm;
pub mod foam;
pub mod lake;
pub mod looping;
pub mod noise;
pub mod ocean;
// The tileable patch and its maps: `tidepool maps` (and the tests).
#[cfg(any(feature = "cli", feature = "testing", test))]
pub mod patch;
pub mod rain;
pub mod ripple;
pub mod sea_state;
pub mod spectra;
pub mod spectrum;
pub mod surface;
pub mod trig;
pub mod wind;
