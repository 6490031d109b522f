//! Outputs: pixels (and heights) in, bytes out. Nothing here knows what it draws.

pub mod apng;
pub mod atomic;
pub mod color;
pub mod cursor;
pub mod diff;
pub mod frame;
pub mod gif;
pub mod halfblock;
pub mod heightmap;
pub mod maps;
pub mod png;
pub mod vt;
