//! The play session (feature `player`): a scene that people play in terminals, as a sans-IO
//! core that any byte stream drives. It does no I/O and reads no clock: bytes and `now` go in,
//! requests and frame bytes come out.
//!
//! - [`Host`]: the only owner of a scene, its clock, its random stones, the scene list and the
//!   recorder. [`Host::apply`] takes a [`Request`].
//! - [`Seat`]: one person: aim, stone size, drag, help, messages, and the [`Fit`] between their
//!   terminal and the scene. [`Seat::handle`] turns an [`Input`] into requests.
//! - [`Screen`]: one terminal: the graphics probe, the link control and byte budget, the
//!   rate-controlled cell encoder and the picture encoders. [`Screen::feed`] takes the
//!   terminal's bytes (replies stay in the screen, inputs come out); `Screen::frame` appends a
//!   frame's bytes.
//!
//! - [`Groups`]: screens alike enough to share frames, encoded once per group; a player's [`Membership`]
//!   takes the group's bytes while its terminal shows the group's model.
//!
//! Two doors drive them: [`crate::tty::run`] (and [`crate::tty::play`], for this process's own terminal) puts a host,
//! a seat and a screen on one terminal; `tidepool serve` runs one host on a thread and a seat
//! and a screen per SSH channel. A key's route is straight: bytes -> [`Screen::feed`] ->
//! [`Input`] -> [`Seat::handle`] -> [`Request`] -> [`Host::apply`] -> the scene.
//!
//! ```
//! use std::time::{Duration, Instant};
//! use tidepool::play::{Bandwidth, Flow, Host, HostConfig, Player, Screen, ScreenConfig};
//! use tidepool::{PoolSettings, SceneSpec};
//!
//! let t0 = Instant::now();
//! let config = ScreenConfig {
//!     fps: 30,
//!     bandwidth: Bandwidth::Unlimited,
//!     color: Default::default(),
//!     color_auto: false,
//!     encode: Default::default(),
//!     graphics: Default::default(),
//!     probe: None,
//!     link_path: Default::default(),
//! };
//! let screen = Screen::new(config, (40, 12), t0);
//! let scenes = vec![SceneSpec::Pool(PoolSettings::default())];
//! let host_config = HostConfig { scenes, seed: 1, record: None, storage: None };
//! let mut host = Host::new(host_config, screen.picture_size(), t0)?;
//! let mut player = Player::new(screen, host.size(), None);
//! // The person presses space: a stone.
//! player.feed(b" ", t0);
//! let mut requests = Vec::new();
//! let turn = player.turn(t0, host.status(), &mut requests);
//! assert_eq!(turn.flow, Flow::Continue);
//! for request in requests {
//!     host.apply(request, t0);
//! }
//! let now = t0 + Duration::from_millis(100);
//! host.advance(now);
//! let mut picture = tiny_skia::Pixmap::new(host.size().0, host.size().1).unwrap();
//! host.render(&mut picture);
//! let mut bytes = Vec::new();
//! player.frame(now, &picture, host.status(), &mut bytes)?;
//! assert!(bytes.starts_with(Screen::ENTER));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod clock;
pub(crate) mod fit;
pub(crate) mod group;
pub(crate) mod host;
pub(crate) mod input;
pub(crate) mod player;
pub(crate) mod replies;
pub(crate) mod request;
pub(crate) mod screen;
pub(crate) mod seat;

pub use fit::Fit;
pub use group::{GroupFeed, GroupKey, Groups, Membership, Source};
pub use host::{Host, HostConfig, Recording, SceneStatus};
pub use input::Input;
pub use player::{Player, Turn};
pub use request::Request;
pub use screen::probe::{Environment, GraphicsChoice, GraphicsRequest, GraphicsSupport, ProbeOptions, WinSize};
pub use screen::{Bandwidth, LinkPath, Screen, ScreenConfig};
pub use seat::{Flow, Seat};

#[cfg(test)]
mod tests;
