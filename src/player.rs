//! The interactive player (feature `player`): a scene full-screen in a terminal, keys and the
//! mouse dropping stones. [`play`] runs it in this process's terminal; [`run`] runs the same
//! loop over any input and output, such as an SSH channel.

pub use crate::term::player::{
    Bandwidth, DEFAULT_STONE_RADIUS, PlayerConfig, STONE_RADII, TEST_PANIC_VAR, TerminalInput, picture_size, run,
};
pub use crate::term::player::{Probed, run_probed};
pub use crate::term::screen::{FrameBuilder, Overlay};
pub use crate::term::tty::{ENTER, RESTORE, play, probe_for_picture, restore, set_restore_prefix};
pub use crate::term::{probe, replies};
