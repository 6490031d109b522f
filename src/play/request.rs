//! What a seat asks of the host: the one vocabulary between a person and the scene they share.

use crate::scene::Action;

/// One thing a person asked the scene for, in scene pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Request {
    /// An action the scene resolves into events (a stone, a stir, rain, damping, a scene key).
    Act(Action),
    /// A stone of this radius at a random spot: the host's random source picks the spot, so a
    /// replay and every viewer of a shared scene agree.
    RandomStone {
        /// Radius in pixels.
        radius: u32,
    },
    /// Pause or resume the simulation (stones still land).
    TogglePause,
    /// The next scene in the list, at the same size.
    NextScene,
    /// Save the scene's picture (exact pixels, no overlays) through the host's storage.
    Screenshot,
}
