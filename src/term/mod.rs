//! The interactive terminal player: the loop that ties a scene to a terminal ([`player`]),
//! input bytes to inputs ([`input`]), time ([`pacing`]), the frame writer ([`writer`]), what is
//! drawn over the picture ([`ui`], [`screen`]), and this process's own terminal ([`tty`]). The
//! bytes themselves come from the pure encoder in [`crate::output::diff`].

pub mod input;
pub mod link;
pub mod pacing;
pub mod picture;
pub mod player;
pub mod probe;
pub mod replies;
pub mod screen;
pub mod tty;
pub mod ui;
pub mod writer;
