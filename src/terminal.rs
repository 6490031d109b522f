//! What a terminal shows, as data: cells of two pixels, colour modes, the frame encoder that
//! turns one screenful into the next with the fewest bytes, and a terminal model that plays
//! those bytes back (for tests, here and in programs that embed tidepool).

pub use crate::output::color::{Color, ColorMode};
pub use crate::output::diff::{EncodeOptions, SYNC_BEGIN, SYNC_END, Shown, encode, encode_into};
pub use crate::output::frame::{Cell, Frame};
pub use crate::output::vt::Screen;
