//! The player's side of a scene: what a key or a click means to it, and what the status line
//! and the help say about it. Kept apart from [`super::Scene`] so that stills, animations and
//! replays never touch it.

use super::Event;

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
    /// their own keys here and list them in [`Controls::help`].
    Key(char),
}

/// How the player talks to a scene.
pub trait Controls {
    /// The events an action causes now (empty when it means nothing to this scene).
    fn resolve(&self, action: Action) -> Vec<Event>;

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
        STONE_HINTS
    }
}

/// The key hints of scenes that take stones, longest first: the first that fits is shown.
pub const STONE_HINTS: &[&str] = &[
    "space stone \u{b7} click drop \u{b7} drag stir \u{b7} arrows+enter aim \u{b7} r rain \u{b7} c clear \u{b7} p pause \u{b7} s shot \u{b7} ? help \u{b7} q quit",
    "space stone \u{b7} click drop \u{b7} ? help \u{b7} q quit",
    "? help \u{b7} q quit",
];
