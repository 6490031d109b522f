//! Outputs: pixels (and heights) in, bytes out. Nothing here knows what it draws.

#[cfg(feature = "animation")]
pub mod apng;
pub mod bucket;
pub mod color;
pub mod cursor;
pub mod diff;
pub mod frame;
#[cfg(feature = "animation")]
pub mod gif;
pub mod graphics;
pub mod halfblock;
pub mod heightmap;
pub mod maps;
pub mod oklab;
pub mod png;
pub mod quality;
pub mod rate;
pub mod ssim;
pub mod units;
pub mod vt;
