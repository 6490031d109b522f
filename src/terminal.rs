//! What a terminal shows, as data: cells of two pixels, colour modes, and the frame encoder
//! that turns one screenful into the next, sending only the cells that changed. The
//! rate-controlled encoder the play session uses (a byte budget spent where the eye sees most)
//! and the terminal model that plays bytes back are in `tidepool::testing` (feature `testing`),
//! for tests and benchmarks.

pub use crate::output::color::{Color, ColorMode};
pub use crate::output::diff::{EncodeOptions, Shown, encode, encode_into};
pub use crate::output::frame::{Cell, Frame};
