//! What a terminal shows, as data: cells of two pixels, colour modes, the frame encoders that
//! turn one screenful into the next (the exact one, and the rate-controlled one that spends a
//! byte budget where the eye sees most), and a terminal model that plays those bytes back, with
//! the picture's quality as seen on it (for tests and benchmarks, here and in programs that
//! embed tidepool).

pub use crate::output::bucket::ByteBucket;
pub use crate::output::color::{Color, ColorMode};
pub use crate::output::diff::{EncodeOptions, SYNC_BEGIN, SYNC_END, Shown, encode, encode_into};
pub use crate::output::frame::{Cell, Frame};
pub use crate::output::quality::{Quality, measure, screen_luma};
pub use crate::output::rate::{RateEncoder, RateOptions, Report, Strategy, Target, UNLIMITED};
pub use crate::output::ssim::{Luma, SsimReference, ssim};
pub use crate::output::vt::TerminalModel;
