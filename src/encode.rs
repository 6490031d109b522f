//! Pixels to bytes: PNG and half-block text (a `Heightmap` writes itself, the sea's maps are
//! `tidepool maps`), and with the `animation`
//! feature animated GIF and PNG. Every encoder returns bytes (or writes to any `Write`); where
//! the bytes go is the caller's choice.

#[cfg(feature = "animation")]
pub use crate::output::apng::ApngWriter;
#[cfg(feature = "animation")]
pub use crate::output::gif::{GifPalette, GifWriter};
pub use crate::output::halfblock::encode as halfblock;
pub use crate::output::png::encode as png;
pub use crate::render::background::decode as decode_image;
