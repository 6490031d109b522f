//! Real pixels in terminals that can show them: the kitty graphics protocol, sixel and iTerm2's
//! inline images, with the geometry that fits a picture to a cell area.
//! Each encoder is pure (a picture in, bytes out) and keeps what it needs to send only what
//! changed ([`Update`] says what went).
//!
//! Chosen, not accumulated: what a program needs to draw pictures in a terminal it owns. The
//! encoders' wire details (chunk sizes, placement ids, tmux passthrough, sixel registers' escape
//! codes) and the rate-controlled picture stream stay inside; the play session ([`crate::play`])
//! uses all of them for you (the stream's knobs are in `tidepool::testing`, for benchmarks).

pub use crate::output::graphics::geometry::{Layout, layout};
pub use crate::output::graphics::{GraphicsMode, Update, push_rgb};

/// The kitty graphics protocol: the encoder and what it needs.
pub mod kitty {
    pub use crate::output::graphics::kitty::{KittyEncoder, KittyOptions, Medium, temp_dir};
}

/// Sixel pictures: the encoder, its palette, and the colour registers a terminal offers.
pub mod sixel {
    pub use crate::output::graphics::sixel::{Registers, SixelEncoder, SixelPalette};
}

/// iTerm2's inline images (also WezTerm's and others').
pub mod iterm2 {
    pub use crate::output::graphics::iterm2::Iterm2Encoder;
}
