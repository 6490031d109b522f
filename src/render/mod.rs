//! Renderers: simulation state in, `tiny_skia::Pixmap` out. Nothing here does I/O except
//! decoding image files the user names.

pub mod background;
pub mod caustics;
pub mod pool;
