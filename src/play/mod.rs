//! The play session (feature `player`): a scene that people play in terminals, as a sans-IO
//! core that any byte stream drives. It does no I/O and reads no clock: bytes and `now` go in,
//! requests and frame bytes come out.
//!
//! - [`Host`]: the only owner of a scene, its clock, its random stones, the scene list and the
//!   recorder. [`Host::apply`] takes a [`Request`].
//! - [`Player`]: one person at one terminal: their seat beside their [`Screen`]. The seat
//!   (crate-private) is what the person holds between frames, apart from any terminal: aim,
//!   stone size, drag, help, messages, the [`Fit`] between their terminal and the scene, and
//!   the one place a key or a click gets its meaning (an input becomes [`Request`]s).
//! - [`Screen`]: one terminal: the graphics probe, the link control and byte budget, the
//!   rate-controlled cell encoder and the picture encoders. It takes the terminal's bytes
//!   (replies stay in the screen, inputs come out) and appends a frame's bytes; its methods
//!   are the crate's, the doors reach it through a [`Driver`].
//!
//! - [`crate::serve::Groups`]: screens alike enough to share frames, encoded once per group
//!   (`tidepool serve`); a player's [`crate::serve::Membership`] takes the group's bytes while
//!   its terminal shows the group's model.
//!
//! The surface the doors drive, in quinn-proto's shape (`handle_*` for inputs, `poll_*` for
//! outputs, time passed in): a [`Driver`] is the one turn of one person at one terminal
//! (`handle_bytes`, `handle_resize`, `handle_picture`, `handle_timeout(now)`; `poll_event`
//! for the seat's requests, a new layout, quit; `poll_timeout`; `poll_frame` and
//! `transmit`); a [`Session`] is a driver beside its own host (`poll_event` adds the host's
//! [`Effect`]s, files to save, and `poll_transmit` hands out a [`Transmit`]: the frame's bytes
//! and the [`FileWrite`]s to do before them). Files, the clock and sockets are the doors'.
//!
//! Two doors drive them: [`crate::tty::run`] (and [`crate::tty::play`], for this process's own
//! terminal) runs a [`Session`] on one terminal; `tidepool serve` runs one host on a thread and
//! a [`Driver`] per SSH channel. A key's route is straight: bytes -> [`Driver::handle_bytes`] ->
//! an input -> the seat -> [`Request`] -> [`Host::apply`] -> the scene.
//!
//! ```
//! use std::time::{Duration, Instant};
//! use tidepool::play::{Bandwidth, HostConfig, Screen, ScreenConfig, Session, Transmit};
//! use tidepool::{PoolSettings, SceneSpec};
//!
//! let t0 = Instant::now();
//! let config = ScreenConfig {
//!     fps: 30,
//!     bandwidth: Bandwidth::Unlimited,
//!     color: Default::default(),
//!     color_auto: false,
//!     colour_hint: false,
//!     encode: Default::default(),
//!     graphics: Default::default(),
//!     probe: None,
//!     link_path: Default::default(),
//! };
//! let scenes = vec![SceneSpec::Pool(PoolSettings::default())];
//! let host = HostConfig { scenes, seed: 1, record: None, screenshots: false };
//! let mut session = Session::new(config, host, (40, 12), None, t0);
//! // The person presses space: a stone. Then a turn, 100 ms later.
//! session.handle_bytes(b" ", t0);
//! let now = t0 + Duration::from_millis(100);
//! session.handle_timeout(now)?;
//! assert!(session.poll_event().is_some(), "the restore prefix, once the host is made");
//! let mut out = Transmit::default();
//! assert!(session.poll_transmit(now, true, &mut out)?);
//! assert!(out.bytes.starts_with(Screen::ENTER) && out.files.is_empty());
//! assert!(session.poll_timeout().is_some_and(|t| t > now), "the next frame, the next step");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod clock;
pub(crate) mod driver;
pub(crate) mod fit;
// Only `tidepool serve` shares frames between screens (and the tests, through `testing`).
#[cfg(any(feature = "serve", feature = "testing", test))]
pub(crate) mod group;
pub(crate) mod host;
pub(crate) mod input;
pub(crate) mod player;
pub(crate) mod replies;
pub(crate) mod request;
pub(crate) mod screen;
pub(crate) mod seat;
pub(crate) mod session;

pub use crate::output::color::ColorMode;
pub use crate::output::diff::EncodeOptions;
pub use crate::output::graphics::GraphicsMode;
pub use crate::output::graphics::stream::FileWrite;
pub use driver::Transmit;
pub use host::{Effect, HostConfig, Recording};
pub use screen::probe::{EnvHints, GraphicsRequest, ProbeOptions, WinSize};
pub use screen::{Bandwidth, LinkPath, ScreenConfig};
pub use session::{Session, SessionEvent};

// The pieces the doors (the terminal door, `tidepool serve`) assemble a session from: the
// crate's, not the API's (a library user drives a [`Session`]).
#[cfg(any(feature = "serve", feature = "testing"))]
pub(crate) use driver::{Driver, DriverEvent, Pacing};
#[cfg(any(feature = "serve", feature = "testing"))]
pub(crate) use fit::Fit;
pub(crate) use host::Host;
#[cfg(any(feature = "serve", feature = "testing"))]
pub(crate) use host::SceneStatus;
pub(crate) use player::Player;
pub(crate) use request::Request;
pub(crate) use screen::Screen;
pub(crate) use screen::probe::{GraphicsChoice, GraphicsSupport};

#[cfg(test)]
pub(crate) mod tests;
