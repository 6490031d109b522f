//! What the terminal player needs from a scene, so that every scene (pool, ocean, lake) is
//! driven the same way: fixed-rate steps, rendering into a pixmap, and user actions turned into
//! recorded events.
//!
//! User input flows one way: the player turns keys and clicks into [`Action`]s, the scene
//! resolves an action into [`Event`]s (making any choice that depends on its state), and the
//! player applies each event with [`Playable::apply`] and records it. A replay applies the same
//! events through the same method, which is what makes a replay bit-identical to the session.

use tiny_skia::Pixmap;

use crate::replay::Event;

/// Something the user asked for, in picture pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Drop a stone centred at `(x, y)`; `big` for the right mouse button.
    Stone {
        /// Centre column in pixels.
        x: i32,
        /// Centre row in pixels.
        y: i32,
        /// Radius in pixels (the player's current stone size).
        radius: u32,
        /// A big stone (right click).
        big: bool,
    },
    /// Stir the water along a dragged path.
    Stir {
        /// Where the drag was.
        from: (i32, i32),
        /// Where it is now.
        to: (i32, i32),
    },
    /// Switch the rain on or off.
    ToggleRain,
    /// Still the water.
    Clear,
    /// Damp more (`true`) or less (`false`).
    Damping(bool),
    /// A key the player does not know; scenes with more parameters (the ocean's wind) bind
    /// their own keys here and list them in [`Playable::help`].
    Key(char),
}

/// A scene the terminal player can drive.
pub trait Playable: Send {
    /// The scene's name, as `tidepool play NAME` spells it.
    fn name(&self) -> &'static str;

    /// Simulation steps per second of wall-clock time.
    fn steps_per_second(&self) -> f64;

    /// The picture size in pixels.
    fn size(&self) -> (u32, u32);

    /// Advances the simulation by one step.
    fn step(&mut self);

    /// Draws the current state into `out`, which has the scene's size.
    fn render(&mut self, out: &mut Pixmap);

    /// The events an action causes now (empty when it means nothing to this scene).
    fn resolve(&self, action: Action) -> Vec<Event>;

    /// Applies an event, live or from a replay. Events of other scenes are ignored.
    fn apply(&mut self, event: &Event);

    /// A short state summary for the status line, e.g. `rain 0.02 · damping 5`.
    fn status(&self, out: &mut String);

    /// The scene's own keys for the help overlay, as (keys, what they do).
    fn help(&self) -> Vec<(&'static str, &'static str)>;

    /// Whether stones (keys, clicks, drags) mean something here; the status line and the help
    /// only mention them when they do.
    fn takes_stones(&self) -> bool {
        true
    }

    /// Key hints for the status line, longest first: the first that fits is shown.
    fn hints(&self) -> &'static [&'static str] {
        crate::term::ui::STONE_HINTS
    }
}
