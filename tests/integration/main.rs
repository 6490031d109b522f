//! tidepool's integration tests, one binary made of modules (as tiny-skia's
//! `tests/integration/main.rs`): pictures rendered in-process against golden images, the
//! command line run as a user runs it, the player in a real pseudo-terminal, replays.
//! The counting-allocator test stays a binary of its own (`tests/steady_state_alloc.rs`): it
//! installs a global allocator.

mod animation;
mod bytes_per_frame;
mod cli;
mod coherence;
mod common;
mod docs;
mod fake_switch;
mod fake_terminals;
mod goldens;
mod graphics;
mod hostile_input;
mod kitty_independent;
mod lake;
mod ocean;
mod player;
mod pool;
mod pool_bits;
mod replay;
mod slow_link;
mod soak;
