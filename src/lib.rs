//! tidepool: water you can play with in any terminal, simulated and drawn on the CPU.
//!
//! Data flows one way: **simulation -> renderer -> pixels -> output**.
//! - [`sim`]: simulations (the ripple pool, rain, the wind-driven sea); no drawing, no I/O.
//! - [`render`]: simulation state -> `tiny_skia::Pixmap`.
//! - [`output`]: pixels -> PNG, half-block text, heightmaps; atomic file writes.
//! - [`scene`]: a simulation together with its renderer, driven alike by the headless
//!   renderer and the terminal player.
//! - [`term`]: the interactive terminal player; [`replay`]: recorded sessions.
//! - [`cli`] and [`commands`]: the command line.
#![warn(missing_docs)]

pub mod cli;
pub mod commands;
pub mod error;
pub mod output;
pub mod progress;
pub mod render;
pub mod replay;
pub mod scene;
pub mod signals;
pub mod sim;
pub mod simd;
pub mod term;

pub use error::{Error, Result};
