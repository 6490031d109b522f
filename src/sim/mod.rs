//! Simulations: state that advances in time. Nothing here draws or does I/O.

pub mod breeze;
pub mod fbm;
pub mod lake;
pub mod noise;
pub mod ocean;
pub mod rain;
pub mod ripple;
pub mod sea_state;
pub mod spectrum;
pub mod surface;
pub mod wind;
