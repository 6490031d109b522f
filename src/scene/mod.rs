//! Scenes: a simulation together with the renderer that draws it. The headless renderer and
//! the terminal player drive the same scene values the same way.

pub mod lake;
pub mod ocean;
pub mod playable;
pub mod pool;
