//! The play session (feature `player`): a scene that people play in terminals, as a sans-IO
//! core that any byte stream drives. It does no I/O and reads no clock: bytes and `now` go in,
//! requests and frame bytes come out.
//!
//! The API is a [`Session`], in quinn-proto's shape (`handle_*` for inputs, `poll_*` for
//! outputs, time passed in): `handle_bytes`, `handle_resize`, `handle_timeout(now)`;
//! `poll_event` for a [`SessionEvent`] (the bytes that restore the terminal, an [`Effect`] such
//! as a screenshot to save, quit), `poll_timeout` for when to come back, and `poll_transmit`
//! for a [`Transmit`]: a frame's bytes and the [`FileWrite`]s to do before them. A
//! [`ScreenConfig`] says how to draw (frame rate, [`Bandwidth`], [`ColorMode`],
//! [`EncodeOptions`], [`GraphicsRequest`] and the [`ProbeOptions`] to find what the terminal
//! shows), a [`HostConfig`] what to play (scenes, seed, a [`Recording`]). Files, the clock and
//! sockets are the caller's.
//!
//! Inside (crate-private, in `tidepool::testing` for the tests): a `Host` is the only owner of
//! a scene; a `Player` is one person at one terminal, their seat beside their `Screen` (the
//! graphics probe, the link control, the encoders); a `Driver` is the one turn every door
//! takes; a `Session` is a driver beside its own host. Two doors drive them: the terminal door
//! (`src/term/`, `tidepool play`) runs a `Session`; `tidepool serve` (`src/cli/serve/`) runs one
//! host on a thread and a `Driver` per SSH channel, and `group.rs` encodes once for screens
//! that are alike.
//!
//! ```
//! use std::time::{Duration, Instant};
//! use tidepool::play::{Bandwidth, HostConfig, ScreenConfig, Session, Transmit};
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
//! // The alternate screen, the cursor hidden, the mouse on: the terminal entered.
//! assert!(out.bytes.starts_with(b"\x1b[?1049h\x1b[?25l") && out.files.is_empty());
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
pub use screen::probe::{GraphicsRequest, ProbeOptions};
pub use screen::{Bandwidth, LinkPath, ScreenConfig};
pub use session::{Session, SessionEvent};

// The pieces the doors (the terminal door, `tidepool serve`) assemble a session from: the
// crate's, not the API's (a library user drives a [`Session`]).
#[cfg(feature = "serve")]
pub(crate) use driver::{Driver, DriverEvent, Pacing};
#[cfg(feature = "serve")]
pub(crate) use fit::Fit;
#[cfg(any(feature = "cli", feature = "testing"))]
pub(crate) use host::Host;
#[cfg(feature = "serve")]
pub(crate) use host::SceneStatus;
#[cfg(any(feature = "cli", feature = "testing"))]
pub(crate) use player::Player;
#[cfg(any(feature = "cli", feature = "testing"))]
pub(crate) use request::Request;
#[cfg(any(feature = "cli", feature = "testing"))]
pub(crate) use screen::Screen;
#[cfg(any(feature = "cli", feature = "testing"))]
pub(crate) use screen::probe::{GraphicsChoice, GraphicsSupport};

#[cfg(test)]
pub(crate) mod tests;
