//! The interactive terminal player: terminal setup and restore ([`guard`]), input
//! ([`input`]), time ([`pacing`]), the frame writer ([`writer`]), overlays ([`ui`]) and the
//! loop that ties them to a scene ([`app`]). The bytes themselves come from the pure encoder in
//! [`crate::output::diff`].

pub mod app;
pub mod guard;
pub mod input;
pub mod pacing;
pub mod probe;
pub mod replies;
pub mod screen;
pub mod ui;
pub mod writer;
