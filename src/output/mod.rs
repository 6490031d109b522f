//! Outputs: pixels (and heights) in, bytes out. Nothing here knows what it draws.

pub mod atomic;
pub mod halfblock;
pub mod heightmap;
pub mod png;
pub mod vt;
