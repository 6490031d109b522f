//! The interactive player (feature `player`): a scene full-screen in a terminal, keys and the
//! mouse dropping stones. [`play`] runs it in this process's terminal; [`run`] runs the same
//! loop over any input and output, such as an SSH channel. A server that shares one scene
//! among many viewers (`tidepool serve`) builds each viewer's frames from the same parts:
//! [`InputParser`] for its bytes, [`SimClock`] for the shared clock, [`FrameBuilder::compose`]
//! with a [`SceneInfo`] for its frames.

pub use crate::term::input::{Input, InputParser, coalesce};
pub use crate::term::pacing::SimClock;
pub use crate::term::player::{
    Bandwidth, DEFAULT_STONE_RADIUS, PlayerConfig, STONE_RADII, TEST_PANIC_VAR, TerminalInput, picture_size, run,
};
pub use crate::term::player::{Probed, run_probed};
pub use crate::term::screen::{FrameBuilder, Overlay, SceneInfo, big_enough};
pub use crate::term::tty::{ENTER, RESTORE, play, probe_for_picture, restore, set_restore_prefix};
pub use crate::term::{probe, replies};
