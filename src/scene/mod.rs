//! Scenes: a simulation together with the renderer that draws it, behind one contract.
//!
//! [`Scene`] is what every path drives the same way: a still picture is frame N of a run, an
//! animation is every k-th frame, a replay applies recorded [`Event`]s at their steps, the
//! player steps at the scene's rate and applies the events its user causes, a benchmark times
//! `advance` and `render`. [`Controls`] is the player's side of a scene: how a key or a click
//! becomes events, and what the status line and the help say. [`SceneSpec`] is the one factory
//! from a scene choice to a boxed scene.
//!
//! User input flows one way: the player turns keys and clicks into [`Action`]s, the scene
//! resolves an action into events (making any choice that depends on its state), and the player
//! applies each event with [`Scene::apply`] and records it. A replay applies the same events
//! through the same method, which is what makes a replay bit-identical to the session.

mod controls;
mod event;
mod heightmap;
pub mod lake;
pub mod ocean;
#[cfg(test)]
mod ocean_physics_tests;
pub mod pool;
mod script;

pub use controls::{Action, Controls};
pub use event::Event;
pub use heightmap::Heightmap;
pub use script::Script;

use tiny_skia::Pixmap;

use crate::error::{Error, Result};

/// A simulation and its renderer: what stills, animations, replays, the player and the
/// benchmarks all drive.
pub trait Scene: Send {
    /// Which scene this is.
    fn kind(&self) -> SceneKind;

    /// The picture size in pixels.
    fn size(&self) -> (u32, u32);

    /// Simulation steps per second of real time (the player's pace; animations follow it).
    fn steps_per_second(&self) -> f64;

    /// Advances the simulation by `steps` steps (identical to that many single steps).
    fn advance(&mut self, steps: u64);

    /// Draws the current state into `out`, which has the scene's size.
    fn render(&mut self, out: &mut Pixmap);

    /// Applies an event, live or from a replay. Events that mean nothing to this scene are
    /// ignored.
    fn apply(&mut self, event: &Event);

    /// Starts drawing at a new size. What happens to the state is the scene's: the pool starts
    /// over with still water (its cells are its pixels), the sea and the lake keep theirs.
    /// On an error nothing changes.
    fn resize(&mut self, width: u32, height: u32) -> Result<()>;

    /// The surface height on a `width x height` grid, row 0 at the top (or north). The pool's
    /// grid is its own cells (its size); the sea and the lake sample their surface.
    fn heightmap(&self, width: usize, height: usize) -> Heightmap;

    /// How the scene draws, for `--stats` (the mesh scenes' supersampling and triangle count);
    /// empty when there is nothing to say.
    fn describe(&self) -> String {
        String::new()
    }

    /// A new picture of the scene now.
    fn snapshot(&mut self) -> Result<Pixmap> {
        let (width, height) = self.size();
        let mut out = Pixmap::new(width, height).ok_or(Error::TooLarge { what: "picture", width, height })?;
        self.render(&mut out);
        Ok(out)
    }
}

/// A scene the terminal player can drive: the simulation and its controls.
pub trait Playable: Scene + Controls {}

impl<T: Scene + Controls> Playable for T {}

/// The scenes tidepool knows, in the order the player's `tab` cycles through them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneKind {
    /// The ripple pool.
    Pool,
    /// The open sea under the wind.
    Ocean,
    /// The lake under a breeze, mirroring its shore.
    Lake,
}

impl SceneKind {
    /// Every scene, in `tab` order.
    pub const ALL: [SceneKind; 3] = [SceneKind::Pool, SceneKind::Ocean, SceneKind::Lake];

    /// The name, as `tidepool play NAME` spells it.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Pool => "pool",
            SceneKind::Ocean => "ocean",
            SceneKind::Lake => "lake",
        }
    }

    /// What a too-large allocation of this scene is called in messages.
    fn noun(self) -> &'static str {
        match self {
            SceneKind::Pool => "pool",
            SceneKind::Ocean => "sea",
            SceneKind::Lake => "lake",
        }
    }
}

impl std::fmt::Display for SceneKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SceneKind {
    type Err = crate::error::ValueError;

    fn from_str(text: &str) -> Result<SceneKind, Self::Err> {
        SceneKind::ALL.into_iter().find(|k| k.name() == text).ok_or_else(|| {
            crate::error::ValueError::new("scene", format!("unknown scene \"{text}\"; use pool, ocean or lake"))
        })
    }
}

/// Everything about a scene except its size: the one factory from a scene choice to a scene.
// Made once per scene and kept beside it: its size costs nothing, and boxing the sea's settings
// would make every caller box them.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum SceneSpec {
    /// The ripple pool.
    Pool(pool::PoolSettings),
    /// The sea.
    Ocean(ocean::OceanSettings),
    /// The lake.
    Lake(lake::LakeSettings),
}

impl SceneSpec {
    /// Which scene this makes.
    pub fn kind(&self) -> SceneKind {
        match self {
            SceneSpec::Pool(_) => SceneKind::Pool,
            SceneSpec::Ocean(_) => SceneKind::Ocean,
            SceneSpec::Lake(_) => SceneKind::Lake,
        }
    }

    /// A new scene drawing `width x height` pictures, at its start.
    ///
    /// Fails with [`Error::TooLarge`] when the (supersampled) picture cannot be allocated.
    pub fn build(&self, width: u32, height: u32) -> Result<Box<dyn Playable>> {
        let too_large = || Error::TooLarge { what: self.kind().noun(), width, height };
        Ok(match self {
            SceneSpec::Pool(s) => Box::new(pool::PoolScene::new(width, height, s.clone()).ok_or_else(too_large)?),
            SceneSpec::Ocean(s) => Box::new(ocean::OceanScene::new(s.clone(), width, height).ok_or_else(too_large)?),
            SceneSpec::Lake(s) => Box::new(lake::LakeScene::new(*s, width, height).ok_or_else(too_large)?),
        })
    }
}
