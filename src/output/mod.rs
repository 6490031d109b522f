//! Outputs: pixels (and heights) in, bytes out. Nothing here knows what it draws.

pub mod apng;
pub mod atomic;
pub mod bucket;
pub mod color;
pub mod cursor;
pub mod diff;
pub mod frame;
pub mod gif;
pub mod halfblock;
pub mod heightmap;
pub mod oklab;
pub mod png;
pub mod quality;
pub mod rate;
pub mod vt;
