//! tidepool: water you can play with in any terminal, simulated and drawn on the CPU.
//!
//! Three scenes — a ripple pool, a wind-driven sea and a lake mirroring its shore — behind one
//! contract, [`Scene`]: advance it, apply [`Event`]s, render it into a `tiny_skia::Pixmap`.
//! Data flows one way: **simulation -> renderer -> pixels -> output** ([`encode`], and a
//! terminal's frames through `play`); nothing flows back except user input, which becomes
//! events.
//!
//! ```
//! use tidepool::{PoolScene, PoolSettings, Scene, Stone};
//!
//! let mut pool = PoolScene::new(64, 48, PoolSettings::default()).expect("a small pool");
//! let still = pool.snapshot()?;
//! pool.drop_stone(Stone::new(32, 24, 6, 128)?);
//! pool.advance(20);
//! let rippled = pool.snapshot()?;
//! assert_ne!(still.pixel(32, 20), rippled.pixel(32, 20), "the ring has moved the floor");
//! let png: Vec<u8> = tidepool::encode::png(&rippled);
//! assert!(png.starts_with(b"\x89PNG"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Features: `cli` (default: the `tidepool` command line, `cli`, which the binary runs),
//! `serve` (its SSH server), `player` (the play session, [`play`]: a sans-IO [`play::Session`]
//! any byte stream drives), `animation` (GIF and animated PNG writers in [`encode`]), `ratatui`
//! (a widget that draws any scene, `widget`), `testing` (the tools the tests and benchmarks
//! check pictures with, and the pieces the doors assemble a session from, `testing`; not part
//! of the chosen API).
#![warn(missing_docs)]
#![warn(unnameable_types)]

mod checks;
mod error;
mod numbers;
mod output;
mod render;
mod scene;
mod sim;
mod simd;
mod size;
// The terminal door (this process's terminal) is the command line's (`tidepool play`) and the
// tests'; a library user with feature `player` drives a `play::Session` on a stream of theirs.
#[cfg(any(feature = "cli", feature = "testing"))]
mod storage;
#[cfg(any(feature = "cli", feature = "testing"))]
mod term;

/// The `tidepool` command line (feature `cli`), as the `tidepool` binary runs it.
#[cfg(feature = "cli")]
pub mod cli;

pub mod encode;
#[cfg(feature = "player")]
pub mod play;
pub mod replay;
pub mod sea;
#[cfg(feature = "ratatui")]
pub mod widget;

/// The tools tidepool's own tests and benchmarks check pictures with (feature `testing`, off by
/// default; `tests/`, `benches/` and `examples/` turn it on through a dev-dependency): a terminal
/// model that plays bytes back and the picture's quality as seen on it (SSIM, PSNR), an
/// independent decoder of kitty's commands, and the knobs of the encoders the play session runs
/// under a link's rate. Not part of the chosen API: they change when the tests need them to,
/// so the API's documentation leaves them out (their own doc comments stay, for the tests'
/// authors: `cargo doc --document-hidden-items`).
#[cfg(feature = "testing")]
#[doc(hidden)]
pub mod testing {
    pub use crate::output::bucket::ByteBucket;
    pub use crate::output::color::Color;
    pub use crate::output::diff::{SYNC_BEGIN, SYNC_END};
    pub use crate::output::diff::{Shown, encode, encode_into};
    pub use crate::output::frame::{Cell, Frame};
    pub use crate::output::graphics::geometry::{Layout, layout};
    pub use crate::output::graphics::iterm2::Iterm2Encoder;
    pub use crate::output::graphics::kitty::{KittyEncoder, KittyOptions, Medium, temp_dir as kitty_temp_dir};
    pub use crate::output::graphics::kitty_decode::{Image as KittyImage, KittyState, decode as kitty_decode};
    pub use crate::output::graphics::lossy_png::Encoder as LossyPngEncoder;
    pub use crate::output::graphics::lossy_png::encode as lossy_png;
    pub use crate::output::graphics::pack::Packing;
    pub use crate::output::graphics::palette_png::Encoder as PalettePngEncoder;
    pub use crate::output::graphics::sixel::dithered_rgb;
    pub use crate::output::graphics::sixel::{Registers, SixelEncoder, SixelPalette};
    pub use crate::output::graphics::stream::ladder::resample;
    pub use crate::output::graphics::stream::{Budget, Offer, Part, PictureStream, Protocol, State};
    pub use crate::output::graphics::{Update, push_rgb};
    pub use crate::output::quality::{Quality, measure, screen_luma};
    pub use crate::output::rate::{RateEncoder, RateOptions, Report, Strategy, Target, UNLIMITED};
    pub use crate::output::ssim::{Luma, SsimReference, ssim};
    pub use crate::output::vt::{ModelCell, TerminalModel};
    pub use crate::play::fit::Fit;
    pub use crate::play::group::{GroupFeed, GroupKey, Groups, Membership, MembershipStats, Source};
    pub use crate::play::host::{Host, SceneStatus};
    pub use crate::play::player::Player;
    pub use crate::play::request::Request;
    pub use crate::play::screen::Screen;
    pub use crate::play::screen::probe::{GraphicsChoice, GraphicsSupport, SixelSupport};
    pub use crate::render::background::load as load_image;
    pub use crate::render::plot::spectrum_plot;
    pub use crate::scene::Script;
    pub use crate::sim::patch::{PatchMaps, PatchSea};
    pub use crate::sim::ripple::RipplePool;
    pub use crate::sim::spectra::{Depth, Jonswap, SeaSpectrum, SpectrumChoice, SpectrumChoiceError, SpectrumKind};
    pub use crate::sim::spectrum::PiersonMoskowitz;
    pub use crate::simd::Simd;
    pub use crate::size::Size;
    pub use crate::storage::Storage;
    pub use crate::term::door::{PlayConfig, TerminalInput, run};
    pub use crate::term::tty::probe_for_picture;
}

pub use error::{Error, Result, ValueError};
pub use render::camera::CameraPose;
pub use render::caustics::CausticsLook;
pub use render::ocean::{OceanView, SeaShading};
pub use render::pool::{PoolLook, Refraction, Sun};
pub use render::supersample::Downsample;
pub use render::texture::SeaTexture;
pub use scene::lake::{LakeScene, LakeSettings};
pub use scene::ocean::{OceanScene, OceanSettings};
pub use scene::pool::{PoolScene, PoolSettings};
pub use scene::{Action, Controls, Event, Heightmap, Playable, Scene, SceneKind, SceneSpec};
pub use sim::breeze::BreezeStyle;
pub use sim::lake::LakeParams;
pub use sim::noise::NoiseKind;
pub use sim::ocean::SeaParams;
pub use sim::ripple::{Damping, Stone};

/// The rust code of the README and the guide, compiled and run as doctests, so that what a
/// newcomer copies from them builds.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
#[doc = include_str!("../docs/GUIDE.md")]
struct DocsExamples;
