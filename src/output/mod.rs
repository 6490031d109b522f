//! Outputs: pixels (and heights) in, bytes out. Nothing here knows what it draws.

#[cfg(feature = "animation")]
pub mod apng;
#[cfg(any(test, feature = "player", feature = "testing"))]
pub mod bucket;
// The terminal's cells and pictures: only the play session (feature `player`) sends them.
#[cfg(any(test, feature = "player"))]
pub mod color;
#[cfg(any(test, feature = "player"))]
pub mod cursor;
#[cfg(any(test, feature = "player"))]
pub mod diff;
#[cfg(any(test, feature = "player"))]
pub mod frame;
#[cfg(feature = "animation")]
pub mod gif;
#[cfg(any(test, feature = "player"))]
pub mod graphics;
pub mod halfblock;
pub mod heightmap;
#[cfg(any(feature = "cli", feature = "testing", test))]
pub mod maps;
#[cfg(any(test, feature = "player"))]
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
