//! Outputs: pixels (and heights) in, bytes out. Nothing here knows what it draws.

#[cfg(feature = "animation")]
pub mod apng;
#[cfg(any(test, feature = "player", feature = "testing"))]
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
#[cfg(any(test, feature = "testing"))]
pub mod quality;
#[cfg(any(test, feature = "player", feature = "testing"))]
pub mod rate;
#[cfg(any(test, feature = "testing"))]
pub mod ssim;
pub mod units;
#[cfg(any(test, feature = "testing"))]
pub mod vt;
