//! Real pixels in terminals that can show them: the kitty graphics protocol, sixel and iTerm2's
//! inline images, with tmux passthrough and the geometry that fits a picture to a cell area.
//! Each encoder is pure (a picture in, bytes out), keeps what it needs to send only what
//! changed, and is tested by decoding its own output. [`PictureStream`] puts one of them under
//! a link's rate (resolution, packing and picture rate chosen per frame); [`AutoSwitch`] is
//! `auto`'s choice between pictures and cells as the link changes.

pub use crate::output::graphics::geometry::{self, Layout, layout};
pub use crate::output::graphics::pack::Packing;
pub use crate::output::graphics::stream::crossover::{AutoSwitch, crossover, truer_mode};
pub use crate::output::graphics::stream::ladder::resample;
pub use crate::output::graphics::stream::{Budget, Offer, Part, PictureStream, Protocol, State};
pub use crate::output::graphics::{GraphicsMode, iterm2, kitty, kitty_decode, push_rgb, rgb, sixel, tmux};
