//! Real pixels in terminals that can show them: the kitty graphics protocol, sixel and iTerm2's
//! inline images, with the geometry that fits a picture to a cell area.
//! Each encoder is pure (a picture in, bytes out), keeps what it needs to send only what
//! changed, and is tested by decoding its own output. [`PictureStream`] puts one of them under
//! a link's rate (resolution, packing and picture rate chosen per frame).
//!
//! Chosen, not accumulated: what a program needs to draw pictures in a terminal it owns. The
//! encoders' wire details (chunk sizes, placement ids, tmux passthrough, sixel registers' escape
//! codes) stay inside; the play session ([`crate::play`]) uses all of them for you.

pub use crate::output::graphics::geometry::{Layout, SCALED_CAP, layout};
pub use crate::output::graphics::stream::ladder::resample;
pub use crate::output::graphics::stream::{Budget, Offer, Part, PictureStream, Protocol, State};
pub use crate::output::graphics::{GraphicsMode, push_rgb};

/// The kitty graphics protocol: the encoder and what it needs.
pub mod kitty {
    pub use crate::output::graphics::kitty::{IMAGE_ID, KittyEncoder, KittyOptions, Medium, temp_dir};
}

/// An independent decoder of the kitty commands tidepool writes: what a kitty terminal would
/// hold after reading them. Tests and benchmarks check the encoders' pictures with it.
pub mod kitty_decode {
    pub use crate::output::graphics::kitty_decode::{Image, KittyState, decode};
}

/// Sixel pictures: the encoder, its palette, and the colour registers a terminal offers.
pub mod sixel {
    pub use crate::output::graphics::sixel::{Registers, SixelEncoder, SixelPalette, dithered_rgb};
}

/// iTerm2's inline images (also WezTerm's and others').
pub mod iterm2 {
    pub use crate::output::graphics::iterm2::Iterm2Encoder;
}
