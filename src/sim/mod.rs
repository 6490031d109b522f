//! Simulations: state that advances in time. Nothing here draws or does I/O.

pub mod rain;
pub mod ripple;
pub mod stepper;
